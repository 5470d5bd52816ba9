#pragma once
/// @file factorized_covariance.h
/// @brief The covariance side of the instance handler (paper §III-A, Jung et al. RA-L 2021):
/// isolated instances with Σ_ii, pending left factors L_i and factorized cross-covariances
/// Σ_ij = L_i S̄_ij S̄_jiᵀ L_jᵀ (storage rule in instance_belief.h), and the two update
/// strategies:
///  - DP: isolated propagation; every update on the full stacked state (assembled from the
///    instances), written back as Σ_ii, L_i = I and, per correlated pair, S̄_ij = Σ_ij on the
///    smaller id, S̄_ji = I on the other. Equal to a dense EKF to rounding.
///  - DAH: an update stacks only the instances P named by the measurement's Jacobian blocks,
///    updates Σ_PP exactly, writes the pair factors within P (S̄_ij = L_i'⁻¹ Σ_ij',
///    S̄_ji = L_j'⁻¹) and folds the correction of the other pairs into the pending factor:
///    Σ_ik' = Σ_ii' Σ_ii⁻¹ Σ_ik for k ∉ P, i.e. L_i ← Σ_ii' Σ_ii⁻¹ L_i (|P| = 1: L_i ← (I − K H) L_i,
///    exact). Cost O(|P|³ + log #partners), independent of the number of instances. P includes
///    the joint sets (joinSet) of the named instances: the pairs inside a set are never approximated.
/// Only the instance a step concerns is written (copy-on-write, so snapshots stay valid).

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "estimator/core/linearization.h"
#include "estimator/core/state_layout.h"
#include "estimator/filter/instance_belief.h"

namespace meshnav::estimator {

class FactorizedCovariance {
 public:
  enum class Mode { DP, DAH };
  /// Re-normalize L_i (S̄_ij ← L_i S̄_ij for all j, L_i ← I) after this many folded steps.
  static constexpr int kMaxLazySteps = 2000;
  /// … or when max|L_i| · max|L_i⁻¹| exceeds this (conditioning of the lazy factor).
  static constexpr double kMaxLazyCondition = 1e8;

  /// Outcome of an update: δx of the stacked participants (`blocks`, offsets into `dx`).
  struct Result {
    bool accepted = false;
    double nis = 0.0;
    std::vector<StateBlock> blocks;
    Eigen::VectorXd dx;
  };

  FactorizedCovariance(Mode mode, bool joseph_form) : mode_(mode), joseph_(joseph_form) {}

  Mode mode() const { return mode_; }
  bool josephForm() const { return joseph_; }
  /// Adds an instance uncorrelated with the others (throws if `id` exists).
  void add(SensorId id, InstanceKind kind, const Eigen::MatrixXd& cov, Timestamp t);
  /// Removes an instance and every partner's factor towards it. False if absent.
  bool remove(SensorId id);
  /// δx_i ← Φ δx_i + w, w ~ N(0, Q): Σ_ii ← Φ Σ_ii Φᵀ + Q, L_i ← Φ L_i. Nothing else changes.
  void propagate(SensorId id, const Eigen::Ref<const Eigen::MatrixXd>& Phi, const Eigen::Ref<const Eigen::MatrixXd>& Q,
                 Timestamp t);
  /// Σ_ii += Q (random walk with Φ = I: the factors do not change).
  void addNoise(SensorId id, const Eigen::MatrixXd& Q, Timestamp t);
  /// EKF update (DP: full state; DAH: the instances named in `lin`). Gated when NIS > nis_gate > 0.
  Result update(const Linearization& lin, double nis_gate, Timestamp t);
  /// S̄_ij ← L_i S̄_ij for every partner j, L_i ← I (exact, O(#partners)).
  void renormalize(SensorId id);
  /// DAH joint set (issue 10; docs/modular_estimator.md, "Joint sets"): merges the instances `ids`
  /// (and the sets they already belong to) into one set whose members always take part together:
  /// a DAH update naming any member stacks all of them, so the correlations among the members
  /// (e.g. the common-mode error of anchors estimated from the same trajectory) are updated exactly
  /// and only the pairs with instances outside the update are approximated. Ids without an instance
  /// are ignored; fewer than two: nothing. DP ignores sets (its updates are full anyway).
  void joinSet(const std::vector<SensorId>& ids);
  /// The members of the joint set holding `id` in ascending id order (empty: none).
  std::vector<SensorId> jointSet(SensorId id) const;
  /// `id` leaves its joint set (a set left with one member is no set). Its correlations with the
  /// members stay and are DAH's from then on: updated exactly by an update that names it, else by
  /// the DAH correction. Nothing when `id` is in no set.
  void leaveSet(SensorId id);

  const StateLayout& layout() const { return layout_; }
  bool has(SensorId id) const { return layout_.find(id) != nullptr; }
  const InstanceBelief& belief(SensorId id) const { return *inst_[index(id)]; }
  /// Shared pointer to the belief (for histories: equal pointers = unchanged belief).
  std::shared_ptr<const InstanceBelief> beliefPtr(SensorId id) const { return inst_[index(id)]; }
  /// Σ_ab (a = b: Σ_aa; else reconstructed from the factors, zero when uncorrelated).
  Eigen::MatrixXd block(SensorId a, SensorId b) const;
  /// The stacked covariance in `layout()` order.
  Eigen::MatrixXd full() const;
  /// Throws std::logic_error naming the problem unless the bookkeeping is consistent (factor pairs
  /// present on both sides with matching sizes, partners exist) and the reconstructed covariance is
  /// symmetric and — DP: positive definite; DAH: positive definite per instance and per correlated
  /// pair (what DAH guarantees; the whole matrix need not be, see the .cpp).
  void checkInvariants(const char* where) const;
  int64_t renormalizations() const { return renormalizations_; }

 private:
  int index(SensorId id) const;
  /// Copy-on-write access to the belief at `k` (and to its dictionary).
  InstanceBelief& mut(int k);
  static FactorDictionary& mutDict(InstanceBelief& b);
  /// Σ_ij for the instances at indices ki ≠ kj.
  Eigen::MatrixXd pairCov(int ki, int kj) const;
  /// The same into `out` (dim_i × dim_j), e.g. a block of the stacked covariance: no temporaries
  /// unless both sides have a pending factor and a stored S̄.
  void pairCovInto(int ki, int kj, Eigen::Ref<Eigen::MatrixXd> out) const;
  void writeBackDp(const std::vector<int>& part, const StateLayout& sub, const Eigen::MatrixXd& P, Timestamp t);
  /// The DAH update: one path for every measurement (factorized_covariance_dah.cpp, class
  /// DahUpdate): the participants P (the named instances and their joint sets), Σ_PP, the EKF update
  /// (scalar: rank-one form; vector: denseEkfUpdate) and the write-back (Σ_ii', L_i, pair factors).
  Result updateDah(const Linearization& lin, double nis_gate, Timestamp t);
  template <int MaxN, int MaxParts>
  friend class DahUpdate;

  /// True when `lin` names a member of a joint set (O(1) without sets: the fast path's cost).
  bool namesJointSet(const Linearization& lin) const;
  /// The participants of a DAH update: the instances named by `lin` and their joint sets'
  /// members (indices in layout order).
  std::vector<int> dahParticipants(const Linearization& lin) const;

  using JointSets = std::vector<std::vector<SensorId>>;  ///< each sorted, ≥ 2 members
  Mode mode_;
  bool joseph_;
  std::shared_ptr<const JointSets> sets_;  ///< null: none (copy-on-write, shared by clones)
  StateLayout layout_;
  std::vector<std::shared_ptr<InstanceBelief>> inst_;  ///< parallel to layout_.blocks()
  int64_t renormalizations_ = 0;
};

}  // namespace meshnav::estimator
