#pragma once
/// @file output_schedule.h
/// @brief What the estimator publishes and when: POSE at `pose_output_rate_hz` on in-order IMU
/// steps, ANCHORS at `anchors_output_rate_hz` and ESTIMATOR_STATUS at `status_rate_hz`, all in
/// data time (the newest input's time, so a replay publishes as often as the live system did).
/// The messages themselves from the filter: `poseOf`, `anchorsOf`.

#include <optional>
#include <vector>

#include "common/messages.h"
#include "common/time.h"
#include "estimator/filter/fusion_strategy.h"
#include "estimator/uwb/uwb_network.h"

namespace meshnav::estimator {

/// The filter's IMU block as a POSE: mean at the filter's time and the marginal covariance of
/// position, velocity and attitude error (rows ImuErr::kP, kV, kTheta).
PoseEstimate poseOf(const FusionStrategy& f);
/// Every anchor the filter knows, sorted by id: the network's exact ones with zero covariance,
/// the estimated ones with their position's marginal covariance.
std::vector<AnchorEstimate> anchorsOf(const FusionStrategy& f, const UwbNetwork& network);

class OutputSchedule {
 public:
  /// Rates in Hz; a pose rate ≤ 0 publishes every IMU step.
  OutputSchedule(double pose_rate_hz, double anchors_rate_hz, double status_rate_hz)
      : pose_rate_hz_(pose_rate_hz), anchors_rate_hz_(anchors_rate_hz), status_rate_hz_(status_rate_hz) {}
  /// A POSE is due at IMU time `t` (and is taken as published).
  bool poseDue(Timestamp t);
  /// ANCHORS / ESTIMATOR_STATUS due at data time `now`: at a fixed period from the first one,
  /// restarted after a pause longer than a period (taken as published).
  bool anchorsDue(Timestamp now) { return periodDue(next_anchors_, anchors_rate_hz_, now); }
  bool statusDue(Timestamp now) { return periodDue(next_status_, status_rate_hz_, now); }
  /// The pose's rate starts over (a re-initialization of the node).
  void resetPose() { last_pose_.reset(); }
  /// Everything starts over (the clock jumped back).
  void resetAll() {
    last_pose_.reset();
    next_anchors_.reset();
    next_status_.reset();
  }

 private:
  static bool periodDue(std::optional<Timestamp>& next, double rate_hz, Timestamp now);
  double pose_rate_hz_, anchors_rate_hz_, status_rate_hz_;
  std::optional<Timestamp> last_pose_, next_anchors_, next_status_;
};

}  // namespace meshnav::estimator
