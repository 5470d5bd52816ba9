#pragma once
/// @file fusion_strategy.h
/// @brief The interface behind which the fusion strategies live (docs/modular_estimator.md): `centralized` (a
/// plain full-covariance error-state EKF, the reference), `dp` and `dah` over isolated instances
/// with factorized cross-covariances (ModularFilter, docs/modular_estimator.md). The node (instance handler) only talks to this interface.

#include <Eigen/Core>
#include <memory>
#include <stdexcept>
#include <string>

#include "estimator/core/linearization.h"
#include "estimator/core/nominal_state.h"
#include "estimator/core/state_layout.h"

namespace meshnav::estimator {

/// Outcome of one update.
struct UpdateResult {
  bool accepted = false;
  double nis = 0.0;  ///< normalized innovation squared rᵀ S⁻¹ r
};

/// Throws std::invalid_argument unless `cov` is square of size 3 + #peers and `biases` holds one γ
/// per peer (the contract of FusionStrategy::addAnchor).
inline void checkAnchorBlock(SensorId id, const Eigen::MatrixXd& cov, const BiasState& biases) {
  const auto k = static_cast<Eigen::Index>(biases.peers.size());
  if (biases.gamma_m.size() != k || cov.rows() != 3 + k || cov.cols() != 3 + k)
    throw std::invalid_argument("addAnchor " + std::to_string(id) + ": covariance " + std::to_string(cov.rows()) + "x" +
                                std::to_string(cov.cols()) + " does not fit 3 + " + std::to_string(k) +
                                " bias states (" + std::to_string(biases.gamma_m.size()) + " values)");
}

class FusionStrategy {
 public:
  virtual ~FusionStrategy() = default;
  virtual std::string name() const = 0;
  /// Deep copy (state snapshot for out-of-sequence rewinds).
  virtual std::unique_ptr<FusionStrategy> clone() const = 0;

  /// (Re)starts the filter with only the IMU instance.
  virtual void reset(SensorId imu_id, const ImuState& x, const ImuMatrix& cov, Timestamp t) = 0;
  /// Adds a barometer bias instance (uncorrelated with the rest).
  virtual void addBaro(SensorId id, double bias_m, double var_m2) = 0;
  /// Adds a downward rangefinder's bias instance (uncorrelated with the rest; random walk
  /// `height.bias_rw_m_per_sqrt_s`). Replaces it if present.
  virtual void addHeight(SensorId id, double bias_m, double var_m2) = 0;
  /// Adds an anchor instance (uncorrelated with the rest; replaces it if present): its position and,
  /// when `biases` has peers, its pair biases γ towards them as states after the position, with
  /// the joint covariance `cov` of [p_AinG, γ] ((3 + #peers)², e.g. the calibration's).
  virtual void addAnchor(SensorId id, const Eigen::Vector3d& p_AinG, const Eigen::MatrixXd& cov,
                         const BiasState& biases = {}) = 0;
  /// Adds a tag instance whose constant biases γ(tag, peer) towards exactly known anchors are
  /// estimated (prior mean `gamma_m`, variances `var_m2`, uncorrelated). Replaces it if present.
  virtual void addTagBiases(SensorId tag_id, const std::vector<SensorId>& peers, const Eigen::VectorXd& gamma_m,
                            const Eigen::VectorXd& var_m2) = 0;
  /// Removes an instance with state (not the IMU). False if absent.
  virtual bool removeInstance(SensorId id) = 0;

  /// Propagates to `t_to` with IMU readings held constant since the state's time.
  virtual void propagate(const Eigen::Vector3d& acc_m_s2, const Eigen::Vector3d& gyro_rad_s, Timestamp t_to) = 0;
  /// Adds Q to the IMU instance's covariance (Σ_II ← Σ_II + Q; cross-covariances unchanged, so
  /// the full matrix stays positive definite). Used for IMU gaps (held readings).
  virtual void addImuNoise(const ImuMatrix& Q) = 0;
  /// EKF update with a linearized measurement; gated when `nis_gate` > 0 and NIS > `nis_gate`.
  virtual UpdateResult update(const Linearization& lin, double nis_gate) = 0;

  virtual const NominalState& state() const = 0;
  virtual const StateLayout& layout() const = 0;
  /// Σ_ab between two instances with state.
  virtual Eigen::MatrixXd covariance(SensorId a, SensorId b) const = 0;
  /// The stacked covariance in `layout()` order (for DP/DAH: reconstructed from Σ_ii and the
  /// factors, Σ_ij = S_ij S_jiᵀ).
  virtual Eigen::MatrixXd fullCovariance() const = 0;
  /// Throws std::logic_error unless the (reconstructed) full covariance is symmetric positive
  /// definite and, for the modular strategies, the factor bookkeeping is consistent.
  virtual void checkInvariants() const = 0;
};

}  // namespace meshnav::estimator
