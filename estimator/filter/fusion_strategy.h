#pragma once
/// @file fusion_strategy.h
/// @brief The interface behind which the fusion strategies live (docs/modular_estimator.md): `centralized` (a
/// plain full-covariance error-state EKF, the reference), `dp` and `dah` over isolated instances
/// with factorized cross-covariances (ModularFilter, docs/modular_estimator.md). The node (instance handler) only talks to this interface.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "estimator/core/linearization.h"
#include "estimator/core/nominal_state.h"
#include "estimator/core/state_layout.h"

namespace meshnav::estimator {

/// Outcome of one update.
struct UpdateResult {
  bool accepted = false;
  double nis = 0.0;  ///< normalized innovation squared rᵀ S⁻¹ r
};

class FusionStrategy {
 public:
  virtual ~FusionStrategy() = default;
  virtual std::string name() const = 0;
  /// Deep copy (state snapshot for out-of-sequence rewinds).
  virtual std::unique_ptr<FusionStrategy> clone() const = 0;

  /// (Re)starts the filter with only the IMU instance.
  virtual void reset(SensorId imu_id, const ImuState& x, const ImuMatrix& cov, Timestamp t) = 0;
  /// Adds an instance `id` of kind K (any registered kind but the IMU; estimator/core/instance_kind.h)
  /// with nominal value `value` and covariance `cov`, uncorrelated with the rest; replaces it if
  /// present. Throws std::invalid_argument when `cov` does not fit `value` (K::check). The
  /// instance's error states then follow K's random walk (K::randomWalk) in every propagation.
  template <class K>
  void addInstance(SensorId id, const typename K::Value& value, const Eigen::MatrixXd& cov) {
    static_assert(!K::kBody, "the IMU instance is set by reset()");
    K::check(id, value, cov);
    if (layout().find(id)) removeInstance(id);
    mutableState().values<K>()[id] = value;
    appendBlock(id, kindOf<K>, cov);
  }
  /// Removes an instance with state (not the IMU). False if absent.
  virtual bool removeInstance(SensorId id) = 0;
  /// Declares that the instances `ids` are updated jointly from now on (DAH joint set, issue 10:
  /// anchors calibrated together; FactorizedCovariance::joinSet). The exact strategies
  /// (centralized, dp) update every instance jointly anyway: nothing to do.
  virtual void joinJointSet(const std::vector<SensorId>& ids) { (void)ids; }
  /// The DAH joint set `id` belongs to (itself included), empty when none or not DAH.
  virtual std::vector<SensorId> jointSetOf(SensorId id) const { (void)id; return {}; }
  /// `id` leaves its DAH joint set (FactorizedCovariance::leaveSet); nothing for the exact strategies.
  virtual void leaveJointSet(SensorId id) { (void)id; }

  /// Propagates to `t_to` with IMU readings held constant since the state's time.
  virtual void propagate(const Eigen::Vector3d& acc_m_s2, const Eigen::Vector3d& gyro_rad_s, Timestamp t_to) = 0;
  /// Starts accumulating the IMU block's error transition: takeTransition() is the identity until the
  /// next propagate(), then Φ_n ⋯ Φ_1 of the propagations since (the fixed-lag smoother's Φ over
  /// one propagation of the node, which may be several steps across an IMU gap; FixedLagSmoother).
  /// Without a startTransition() since the last takeTransition() nothing is accumulated: the
  /// filter's propagation pays for it only while the fixed-lag smoother records.
  void startTransition() {
    transition_ = ImuMatrix::Identity();
    tracking_ = true;
  }
  /// The product of the IMU block's Φ since startTransition() (addImuNoise changes no Φ); ends
  /// the accumulation.
  const ImuMatrix& takeTransition() {
    tracking_ = false;
    return transition_;
  }
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

 private:
  ImuMatrix transition_ = ImuMatrix::Identity();
  bool tracking_ = false;  ///< between startTransition() and takeTransition()

 protected:
  /// Every propagate() records its step's Φ here (takeTransition(), while tracking).
  void noteTransition(const ImuMatrix& Phi) {
    if (tracking_) transition_ = Phi * transition_;
  }
  /// The nominal state addInstance writes the new value into.
  virtual NominalState& mutableState() = 0;
  /// Appends a block of kind `kind` with covariance `cov` (its dimension), uncorrelated with the
  /// others; the nominal value is already in mutableState().
  virtual void appendBlock(SensorId id, InstanceKind kind, const Eigen::MatrixXd& cov) = 0;
};

}  // namespace meshnav::estimator
