#pragma once
/// @file control_loop.h
/// @brief When the ControllerNode runs in a process fed by messages (the `controller` process,
/// docs/closed_loop.md "Over LCM"); free of LCM.
///
/// The node runs once per POSE, at the POSE's time (the estimator publishes one POSE per IMU
/// sample once initialized, right after that sample): its command answers that IMU sample. It runs
/// once per IMU sample instead when no POSE will answer it — before the first POSE, or when the
/// newest POSE is older than `pose_timeout_s` at the sample's time (the estimator is down or lost:
/// the idle pad and the failsafe still answer). Each update at most once per data time and in
/// increasing time: a POSE or IMU sample not newer than the last update is not answered again.

#include <functional>
#include <optional>

#include "common/types.h"
#include "controller/controller_node.h"
#include "controller/setpoint.h"

namespace meshnav::controller {

class ControlLoop {
 public:
  /// `command` gets every command with the update time in `ControlCommand::t`.
  ControlLoop(ControllerNode& node, double pose_timeout_s, std::function<void(const ControlCommand&)> command);

  void onImu(Timestamp t);
  void onPose(const PoseEstimate& pose);
  void onFlightState(const FlightStateSample& fs) { node_.onFlightState(fs); }

  int64_t updates() const { return updates_; }
  /// Updates made on an IMU sample (no POSE to answer it).
  int64_t imuUpdates() const { return imu_updates_; }
  std::optional<Timestamp> lastUpdate() const { return last_update_; }

 private:
  void run(Timestamp t);

  ControllerNode& node_;
  double pose_timeout_s_;
  std::function<void(const ControlCommand&)> command_;
  std::optional<Timestamp> newest_pose_, last_update_;
  int64_t updates_ = 0, imu_updates_ = 0;
};

}  // namespace meshnav::controller
