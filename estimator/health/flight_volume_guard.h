#pragma once
/// @file flight_volume_guard.h
/// @brief The flight volume as a constraint on the estimate (setup.yaml `flight_volume`,
/// FlightVolumeOptions, docs/robustness.md "The flight volume").
///
/// Ranges to coplanar known anchors cannot tell a position from its mirror image across their
/// plane (AnchorPlaneMirror). The vehicle is known to be inside the volume, on one side of that
/// plane; two models follow:
///  - **The mirror image**: an estimate more than `flight_volume.mirror_margin_m` outside the volume
///    whose mirror image is inside *is* that mirror image: position and velocity are reflected with
///    J = diag(I, M, M, I…) on (θ, p, v, …), M = I − 2nnᵀ, and P ← J P Jᵀ (`mirrorImage`).
///  - **The side of the plane**: otherwise the position's Gaussian along the inward normal n,
///    d ~ N(μ, nᵀP_pp n), is truncated to d ≥ 0 (Simon's PDF truncation) as a scalar pseudo-
///    measurement with H = nᵀ on δp (`sideConstraint`), at most `flight_volume.side_constraint_rate_hz`.
/// Without a stated volume, or when the known anchors do not bound it, the guard does nothing.

#include <optional>

#include "common/diagnostics.h"
#include "common/setup.h"
#include "estimator/core/estimator_options.h"
#include "estimator/core/imu_state.h"
#include "estimator/core/linearization.h"
#include "estimator/health/anchor_plane_mirror.h"

namespace meshnav::estimator {

class FlightVolumeGuard {
 public:
  /// Active when `options.enabled`, the setup states a flight volume and its known anchors make a
  /// bounding plane (AnchorPlaneMirror::of).
  FlightVolumeGuard(const FlightVolumeOptions& options, const SystemSetup& setup, Diagnostics& diag);
  bool active() const { return mirror_.has_value(); }
  /// The plane the guard uses (none when inactive).
  const std::optional<AnchorPlaneMirror>& plane() const { return mirror_; }

  /// The reflected IMU state and covariance when `x` is a mirror image (counted
  /// "mirrored_into_flight_volume", logged at `t`); nullopt otherwise.
  struct Reflected {
    ImuState x;
    ImuMatrix P;
  };
  std::optional<Reflected> mirrorImage(Timestamp t, const ImuState& x, const ImuMatrix& P) const;
  /// The truncation to the volume's side at `t` as a pseudo-measurement on the IMU block `imu_id`
  /// (position covariance `P_pp`), when one is due by the rate and it would move the estimate
  /// (counted "flight_volume_side_constraint").
  std::optional<Linearization> sideConstraint(Timestamp t, SensorId imu_id, const Eigen::Vector3d& p_IinG,
                                              const Eigen::Matrix3d& P_pp);
  /// A side constraint is due at `t` (the rate).
  bool sideConstraintDue(Timestamp t) const;
  /// True when `p_IinG` lies beyond the margin outside and its mirror image inside.
  bool isMirrorImage(const Eigen::Vector3d& p_IinG) const {
    return mirror_ && mirror_->isMirrorImage(p_IinG, options_.mirror_margin_m);
  }
  /// Forgets the rate limit's last time (a reset of the node).
  void reset() { last_side_constraint_.reset(); }

 private:
  FlightVolumeOptions options_;
  std::optional<FlightVolume> volume_;
  Diagnostics& diag_;
  std::optional<AnchorPlaneMirror> mirror_;
  std::optional<Timestamp> last_side_constraint_;
};

}  // namespace meshnav::estimator
