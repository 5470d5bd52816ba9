#include "controller/controller_node.h"

#include <algorithm>
#include <cmath>

namespace meshnav::controller {

namespace {
constexpr double kGravity_m_s2 = 9.81;

double yawOf(const Eigen::Matrix3d& R) { return std::atan2(R(1, 0), R(0, 0)); }
}  // namespace

const char* toString(ControlMode m) {
  switch (m) {
    case ControlMode::Idle: return "idle";
    case ControlMode::Flying: return "flying";
    case ControlMode::Failsafe: return "failsafe";
    case ControlMode::Landed: return "landed";
  }
  return "?";
}

ControllerNode::ControllerNode(const ControllerOptions& options, mission::FlightPlan plan, ControllerSinks sinks,
                               double status_rate_hz)
    : options_(options),
      follower_(std::move(plan)),
      pc_(options),
      sinks_(std::move(sinks)),
      status_period_s_(status_rate_hz > 0.0 ? 1.0 / status_rate_hz : 0.0) {
  options_.validate();
}

void ControllerNode::onPose(const PoseEstimate& pose) {
  if (pose_ && pose.t < pose_->t) return;
  pose_ = pose;
}

void ControllerNode::onFlightState(const FlightStateSample& fs) { landed_flag_ = fs.landed; }

std::string ControllerNode::poseProblem(Timestamp now) const {
  if (!pose_) return "no POSE";
  const double age = (now - pose_->t).sec();
  if (age > options_.pose_timeout_s) return "POSE late";
  const double trace = pose_->cov_p_m2.trace();
  if (!std::isfinite(trace) || trace > options_.max_position_cov_trace_m2) return "POSE covariance too large";
  if (!pose_->p_IinG.allFinite() || !pose_->v_IinG.allFinite() || !pose_->q_ItoG.coeffs().allFinite())
    return "POSE not finite";
  return "";
}

ControlCommand ControllerNode::update(Timestamp now) {
  if (!t0_) t0_ = now;
  const double dt = last_update_ ? std::clamp((now - *last_update_).sec(), 0.0, 0.1) : 0.0;
  last_update_ = now;
  const std::string problem = poseProblem(now);
  const bool healthy = problem.empty();
  // The attitude: the newest POSE's, carried on with the body rates commanded since (what the
  // vehicle's rate loop follows), so that a late POSE does not leave the attitude loop blind.
  if (pose_ && (!attitude_from_ || pose_->t != *attitude_from_)) {
    attitude_R_ = pose_->q_ItoG.normalized().toRotationMatrix();
    attitude_from_ = pose_->t;
    if (last_cmd_.w_IinI.norm() > 0.0 && now > pose_->t) {
      const double since = (now - pose_->t).sec();
      attitude_R_ = attitude_R_ * Eigen::AngleAxisd(last_cmd_.w_IinI.norm() * since, last_cmd_.w_IinI.normalized())
                                      .toRotationMatrix();
    }
  } else if (last_cmd_.w_IinI.norm() > 0.0) {
    attitude_R_ = attitude_R_ * Eigen::AngleAxisd(last_cmd_.w_IinI.norm() * dt, last_cmd_.w_IinI.normalized())
                                    .toRotationMatrix();
  }
  const Eigen::Matrix3d R = attitude_R_;

  ControlCommand cmd;
  cmd.t = now;
  Setpoint sp;
  std::string phase;
  switch (mode_) {
    case ControlMode::Idle:
      if (healthy && (now - *t0_).sec() >= follower_.plan().takeoff_at_s) {
        mode_ = ControlMode::Flying;
        takeoff_begin_ = now;
        pc_.reset();
      }
      break;
    case ControlMode::Flying:
      if (!healthy) {
        mode_ = ControlMode::Failsafe;
        ++status_.failsafe_events;
        status_.failsafe_reason = problem;
        failsafe_yaw_rad_ = yawOf(R);
        healthy_since_.reset();
      }
      break;
    case ControlMode::Failsafe:
      if (landed_flag_) {
        mode_ = ControlMode::Landed;
      } else if (healthy) {
        if (!healthy_since_) healthy_since_ = now;
        if ((now - *healthy_since_).sec() >= options_.recover_after_s) {
          mode_ = ControlMode::Flying;
          if (follower_started_) follower_.resumeFrom(now.sec(), pose_->p_IinG, yawOf(R));
        }
      } else {
        healthy_since_.reset();
      }
      break;
    case ControlMode::Landed:
      break;
  }

  if (mode_ == ControlMode::Flying) {
    const double since = (now - *takeoff_begin_).sec();
    if (!follower_started_ && since < options_.spin_up_s) {
      phase = "spinup";
      cmd.thrust_m_s2 = 0.9 * kGravity_m_s2 * since / options_.spin_up_s;
    } else {
      if (!follower_started_) {
        follower_.start(now.sec(), pose_->p_IinG, yawOf(R));
        follower_started_ = true;
      }
      sp = follower_.setpoint(now.sec());
      phase = WaypointFollower::toString(follower_.phase());
      const ControlCommand c = pc_.compute(pose_->p_IinG, pose_->v_IinG, R, sp, dt);
      cmd.thrust_m_s2 = c.thrust_m_s2;
      cmd.w_IinI = c.w_IinI;
      // Touch-down at the end of the landing: motors off.
      if (follower_.landing() && landed_flag_) {
        mode_ = ControlMode::Landed;
        cmd.thrust_m_s2 = 0.0;
        cmd.w_IinI.setZero();
      }
    }
  } else if (mode_ == ControlMode::Failsafe) {
    const ControlCommand c = pc_.levelDescent(R, failsafe_yaw_rad_, options_.failsafe_descent_acc_m_s2);
    cmd.thrust_m_s2 = c.thrust_m_s2;
    cmd.w_IinI = c.w_IinI;
  }
  last_cmd_ = cmd;

  status_.t = now;
  status_.mode = mode_;
  status_.phase = phase;
  status_.waypoint = follower_started_ ? follower_.waypointIndex() : -1;
  status_.pose_age_s = pose_ ? (now - pose_->t).sec() : -1.0;
  status_.position_cov_trace_m2 = pose_ ? pose_->cov_p_m2.trace() : 0.0;
  status_.setpoint = sp;
  status_.command = cmd;
  status_.mission_complete = mode_ == ControlMode::Landed && follower_started_ && follower_.landing();
  if (sinks_.status && (!last_status_ || (now - *last_status_).sec() >= status_period_s_ - 1e-9)) {
    last_status_ = now;
    sinks_.status(status_);
  }
  return cmd;
}

}  // namespace meshnav::controller
