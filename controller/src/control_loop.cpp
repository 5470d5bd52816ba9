#include "controller/control_loop.h"

namespace meshnav::controller {

ControlLoop::ControlLoop(ControllerNode& node, double pose_timeout_s,
                         std::function<void(const ControlCommand&)> command)
    : node_(node), pose_timeout_s_(pose_timeout_s), command_(std::move(command)) {}

void ControlLoop::onImu(Timestamp t) {
  if (last_update_ && t <= *last_update_) return;
  // A POSE of this sample is to come unless the estimator is silent (none yet, or too old).
  if (newest_pose_ && (t - *newest_pose_).sec() <= pose_timeout_s_) return;
  ++imu_updates_;
  run(t);
}

void ControlLoop::onPose(const PoseEstimate& pose) {
  node_.onPose(pose);
  if (!newest_pose_ || pose.t > *newest_pose_) newest_pose_ = pose.t;
  if (last_update_ && pose.t <= *last_update_) return;
  run(pose.t);
}

void ControlLoop::run(Timestamp t) {
  last_update_ = t;
  ++updates_;
  const ControlCommand c = node_.update(t);
  if (command_) command_(c);
}

}  // namespace meshnav::controller
