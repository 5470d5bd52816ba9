#pragma once
/// @file instance_belief.h
/// @brief One isolated filter instance (paper §III-A): its belief block Σ_ii, its pending left
/// factor L_i and its dictionary id_j → S̄_ij of factorized cross-covariance factors.
///
/// Storage rule (docs/modular_estimator.md): Σ_ij = S_ij S_jiᵀ with S_ij = L_i S̄_ij. When a joint
/// update writes the pair (i, j), the instance with the **smaller id** stores the cross-covariance
/// (S_ij = Σ_ij, dim_i × dim_j) and the other one the identity (S_ji = I, dim_j × dim_j). Stored
/// relative to the pending factor: S̄_ij = L_i⁻¹ S_ij. A step that changes only instance i by
/// δx_i ← M δx_i (propagation Φ, private update I − K H, DAH correction Σ_ii' Σ_ii⁻¹) sets
/// L_i ← M L_i and leaves every factor (its own and the partners') untouched.
///
/// Copy-on-write: beliefs, dictionaries and factor matrices are shared between snapshots (the
/// node's out-of-sequence history) and never modified once shared; the owner copies before
/// writing. A snapshot of all instances is therefore O(#instances) pointer copies, and the
/// sequence of snapshots is each instance's belief and factor history.

#include <Eigen/Core>
#include <algorithm>
#include <memory>
#include <vector>

#include "common/time.h"
#include "common/types.h"
#include "estimator/core/instance_kind.h"

namespace meshnav::estimator {

/// The factor S̄_ij that instance i holds for partner j (null: the identity).
struct FactorEntry {
  SensorId partner = 0;
  std::shared_ptr<const Eigen::MatrixXd> S_bar;
};

/// Sorted dictionary partner id → S̄_ij. Copying it copies pointers only.
class FactorDictionary {
 public:
  /// The entry for `partner`, or nullptr when the pair is uncorrelated (Σ_ij = 0).
  const FactorEntry* find(SensorId partner) const {
    auto it = lower(partner);
    return it != entries_.end() && it->partner == partner ? &*it : nullptr;
  }
  /// Inserts or replaces (null `S_bar` = identity).
  void set(SensorId partner, std::shared_ptr<const Eigen::MatrixXd> S_bar) {
    auto it = lower(partner);
    if (it != entries_.end() && it->partner == partner)
      it->S_bar = std::move(S_bar);
    else
      entries_.insert(it, FactorEntry{partner, std::move(S_bar)});
  }
  /// The entry for `partner`, inserted with a null S̄ when absent (to be written by the caller).
  FactorEntry& slot(SensorId partner) {
    auto it = lower(partner);
    if (it == entries_.end() || it->partner != partner) it = entries_.insert(it, FactorEntry{partner, nullptr});
    return *it;
  }
  bool erase(SensorId partner) {
    auto it = lower(partner);
    if (it == entries_.end() || it->partner != partner) return false;
    entries_.erase(it);
    return true;
  }
  std::vector<FactorEntry>& entries() { return entries_; }
  const std::vector<FactorEntry>& entries() const { return entries_; }
  size_t size() const { return entries_.size(); }

 private:
  std::vector<FactorEntry>::iterator lower(SensorId p) {
    return std::lower_bound(entries_.begin(), entries_.end(), p,
                            [](const FactorEntry& e, SensorId id) { return e.partner < id; });
  }
  std::vector<FactorEntry>::const_iterator lower(SensorId p) const {
    return std::lower_bound(entries_.begin(), entries_.end(), p,
                            [](const FactorEntry& e, SensorId id) { return e.partner < id; });
  }
  std::vector<FactorEntry> entries_;
};

/// Belief of one instance (the nominal x_i lives in NominalState, addressed by id).
struct InstanceBelief {
  SensorId id = 0;
  InstanceKind kind = kindOf<ImuKind>;
  int dim = 0;
  Timestamp t;                 ///< time of the last change of this block
  Eigen::MatrixXd Sigma;       ///< Σ_ii (dim × dim)
  Eigen::MatrixXd L;           ///< pending left factor L_i (empty: identity)
  int lazy_steps = 0;          ///< multiplications folded into L_i since the last re-normalization
  /// L_i⁻¹ of the current L_i as a DAH update stored it as the larger id's S̄_ji (null: none since
  /// L_i last changed). A partner's entry holding this very matrix stands for S_ji = L_i S̄_ji = I,
  /// which is then not multiplied out (FactorizedCovariance::pairCovInto).
  std::shared_ptr<const Eigen::MatrixXd> L_inv;
  /// id_j → S̄_ij; shared between snapshots, never modified while shared (use_count() > 1).
  std::shared_ptr<FactorDictionary> factors = std::make_shared<FactorDictionary>();
};

}  // namespace meshnav::estimator
