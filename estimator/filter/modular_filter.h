#pragma once
/// @file modular_filter.h
/// @brief Strategies `dp` and `dah` (docs/modular_estimator.md): the nominal state of
/// every instance (NominalState, addressed by id) plus the isolated instance beliefs with
/// factorized cross-covariances (FactorizedCovariance).
///
/// - Propagation is isolated: only the IMU instance (x_I, Σ_II, L_I ← Φ L_I) and the instances
///   whose kind has a random walk (Σ_kk += σ_k² Δt I, e.g. the baro bias) change; no factor is
///   touched.
/// - DP: every update on the full stacked state (equal to `centralized` to rounding). A private
///   measurement (ZUPT) is a full update too: the exact update also corrects the means of the
///   instances correlated with the IMU (K_k = Σ_kI Hᵀ S⁻¹ ≠ 0).
/// - DAH: an update stacks the instances named by the measurement (ZUPT: {IMU}; baro: {IMU, baro};
///   tag–anchor range: {IMU, anchor} or {IMU, tag} for an estimated γ; anchor–anchor: {a, b}); the
///   others' means are not corrected and their correlations are approximated. A joint set
///   (joinJointSet) takes part as a whole whenever a member is named.
/// clone() copies pointers only (copy-on-write instances): cheap snapshots for the node's rewinds.

#include "estimator/filter/factorized_covariance.h"
#include "estimator/filter/fusion_strategy.h"
#include "estimator/imu/imu_propagator.h"

namespace meshnav::estimator {

class ModularFilter final : public FusionStrategy {
 public:
  using Mode = FactorizedCovariance::Mode;
  /// `random_walks`: σ of each kind's random walk (KindRandomWalks::fromOptions).
  ModularFilter(Mode mode, const ImuPropagator& propagator, const KindRandomWalks& random_walks, bool joseph_form);

  std::string name() const override { return cov_.mode() == Mode::DP ? "dp" : "dah"; }
  std::unique_ptr<FusionStrategy> clone() const override { return std::make_unique<ModularFilter>(*this); }

  void reset(SensorId imu_id, const ImuState& x, const ImuMatrix& cov, Timestamp t) override;
  bool removeInstance(SensorId id) override;
  void joinJointSet(const std::vector<SensorId>& ids) override {
    if (cov_.mode() == Mode::DAH) cov_.joinSet(ids);
  }
  std::vector<SensorId> jointSetOf(SensorId id) const override {
    return cov_.mode() == Mode::DAH ? cov_.jointSet(id) : std::vector<SensorId>{};
  }
  void leaveJointSet(SensorId id) override { cov_.leaveSet(id); }

  void propagate(const Eigen::Vector3d& acc_m_s2, const Eigen::Vector3d& gyro_rad_s, Timestamp t_to) override;
  void addImuNoise(const ImuMatrix& Q) override;
  UpdateResult update(const Linearization& lin, double nis_gate) override;

  const NominalState& state() const override { return x_; }
  const StateLayout& layout() const override { return cov_.layout(); }
  Eigen::MatrixXd covariance(SensorId a, SensorId b) const override { return cov_.block(a, b); }
  Eigen::MatrixXd fullCovariance() const override { return cov_.full(); }
  void checkInvariants() const override { cov_.checkInvariants("explicit check"); }

  /// The instances (beliefs, pending factors, factor dictionaries).
  const FactorizedCovariance& instances() const { return cov_; }
  /// Folds instance `id`'s pending factor into its factors (exact; for tests and maintenance).
  void renormalize(SensorId id) { cov_.renormalize(id); }

 protected:
  NominalState& mutableState() override { return x_; }
  void appendBlock(SensorId id, InstanceKind kind, const Eigen::MatrixXd& cov) override {
    cov_.add(id, kind, cov, x_.t);
  }

 private:
  void checkAfter(const char* where) const;

  ImuPropagator propagator_;
  KindRandomWalks random_walks_;
  NominalState x_;
  FactorizedCovariance cov_;
};

}  // namespace meshnav::estimator
