#pragma once
/// @file centralized_ekf.h
/// @brief Strategy `centralized`: one error-state EKF over the stacked state of all instances
/// with state, one dense covariance P. The reference that DP must equal.
///
/// Propagation (only the IMU block moves): P_II ← Φ P_II Φᵀ + Q, P_Ij ← Φ P_Ij,
/// every other instance's error states gain σ_k² Δt (σ_k: its kind's random walk, KindRandomWalks).
/// Update: U = P Hᵀ (from the named blocks), S = H U + R, K = U S⁻¹, δx = K r,
/// P ← P − K Uᵀ − U Kᵀ + K S Kᵀ (Joseph form, valid for any K) or P ← P − K Uᵀ, then symmetrized;
/// x ← x ⊞ δx.

#include "estimator/filter/fusion_strategy.h"
#include "estimator/imu/imu_propagator.h"

namespace meshnav::estimator {

class CentralizedEkf final : public FusionStrategy {
 public:
  /// `random_walks`: σ of each kind's random walk (KindRandomWalks::fromOptions).
  CentralizedEkf(const ImuPropagator& propagator, const KindRandomWalks& random_walks, bool joseph_form);

  std::string name() const override { return "centralized"; }
  std::unique_ptr<FusionStrategy> clone() const override { return std::make_unique<CentralizedEkf>(*this); }

  void reset(SensorId imu_id, const ImuState& x, const ImuMatrix& cov, Timestamp t) override;
  bool removeInstance(SensorId id) override;

  void propagate(const Eigen::Vector3d& acc_m_s2, const Eigen::Vector3d& gyro_rad_s, Timestamp t_to) override;
  void addImuNoise(const ImuMatrix& Q) override;
  UpdateResult update(const Linearization& lin, double nis_gate) override;

  const NominalState& state() const override { return x_; }
  const StateLayout& layout() const override { return layout_; }
  Eigen::MatrixXd covariance(SensorId a, SensorId b) const override;
  Eigen::MatrixXd fullCovariance() const override { return P_; }
  void checkInvariants() const override;

 protected:
  NominalState& mutableState() override { return x_; }
  /// Appends a block with covariance `cov`, uncorrelated with the others (dim = cov.rows()).
  void appendBlock(SensorId id, InstanceKind kind, const Eigen::MatrixXd& cov) override;

 private:
  void checkInvariants(const char* where) const;

  ImuPropagator propagator_;
  KindRandomWalks random_walks_;
  bool joseph_form_;
  NominalState x_;
  StateLayout layout_;
  Eigen::MatrixXd P_;
  /// Working memory of propagate(): no allocation per IMU step once the state stops growing, and
  /// not copied with the filter (every stored input keeps a copy of it, FilterContext).
  struct Scratch {
    Eigen::Matrix<double, Eigen::Dynamic, ImuErr::kDim> cols;  ///< P_·I Φᵀ
    Scratch() = default;
    Scratch(const Scratch&) {}
    Scratch& operator=(const Scratch&) { return *this; }
  };
  Scratch scratch_;
};

}  // namespace meshnav::estimator
