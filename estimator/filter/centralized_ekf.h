#pragma once
/// @file centralized_ekf.h
/// @brief Strategy `centralized`: one error-state EKF over the stacked state of all instances
/// with state, one dense covariance P. The reference that DP must equal.
///
/// Propagation (only the IMU block moves): P_II ← Φ P_II Φᵀ + Q, P_Ij ← Φ P_Ij,
/// baro biases gain σ_b² Δt. Update: U = P Hᵀ (from the named blocks), S = H U + R,
/// K = U S⁻¹, δx = K r, P ← P − K Uᵀ − U Kᵀ + K S Kᵀ (Joseph form, valid for any K) or
/// P ← P − K Uᵀ, then symmetrized; x ← x ⊞ δx.

#include "estimator/filter/fusion_strategy.h"
#include "estimator/imu/imu_propagator.h"

namespace meshnav::estimator {

class CentralizedEkf final : public FusionStrategy {
 public:
  /// `height_bias_rw_m_per_sqrt_s`: random walk of every height bias instance.
  CentralizedEkf(const ImuPropagator& propagator, double baro_bias_rw_m_per_sqrt_s, bool joseph_form,
                 double height_bias_rw_m_per_sqrt_s = 0.0);

  std::string name() const override { return "centralized"; }
  std::unique_ptr<FusionStrategy> clone() const override { return std::make_unique<CentralizedEkf>(*this); }

  void reset(SensorId imu_id, const ImuState& x, const ImuMatrix& cov, Timestamp t) override;
  void addBaro(SensorId id, double bias_m, double var_m2) override;
  void addHeight(SensorId id, double bias_m, double var_m2) override;
  void addAnchor(SensorId id, const Eigen::Vector3d& p_AinG, const Eigen::MatrixXd& cov,
                 const BiasState& biases = {}) override;
  void addTagBiases(SensorId tag_id, const std::vector<SensorId>& peers, const Eigen::VectorXd& gamma_m,
                    const Eigen::VectorXd& var_m2) override;
  bool removeInstance(SensorId id) override;

  void propagate(const Eigen::Vector3d& acc_m_s2, const Eigen::Vector3d& gyro_rad_s, Timestamp t_to) override;
  void addImuNoise(const ImuMatrix& Q) override;
  UpdateResult update(const Linearization& lin, double nis_gate) override;

  const NominalState& state() const override { return x_; }
  const StateLayout& layout() const override { return layout_; }
  Eigen::MatrixXd covariance(SensorId a, SensorId b) const override;
  Eigen::MatrixXd fullCovariance() const override { return P_; }
  void checkInvariants() const override;

 private:
  /// Appends a block with covariance `cov`, uncorrelated with the others.
  void appendBlock(SensorId id, InstanceKind kind, const Eigen::MatrixXd& cov);  // dim = cov.rows()
  void checkInvariants(const char* where) const;

  ImuPropagator propagator_;
  double baro_bias_rw_;
  double height_bias_rw_ = 0.0;
  bool joseph_form_;
  NominalState x_;
  StateLayout layout_;
  Eigen::MatrixXd P_;
};

}  // namespace meshnav::estimator
