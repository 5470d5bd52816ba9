#pragma once
/// @file controller_node.h
/// @brief The controller node (issue 37, docs/closed_loop.md), free of LCM: flies a flight plan
/// (mission/flight_plan.h) on the estimated POSE and its covariance only — never the truth — and
/// reports CONTROL_STATUS.
///
/// Attitude: the loops use the newest POSE's attitude carried on with the body rates commanded since,
/// R ← R Exp(ω_c Δt) (what the vehicle's rate loop follows): a POSE that is late leaves the attitude
/// loop on a prediction rather than on a frozen attitude.
/// Modes:
///  - `idle`: on the pad, motors off, until `takeoff_at` (after the first update) with a healthy POSE;
///  - `flying`: spin-up (thrust ramp over `spin_up_s`, zero rates), then the WaypointFollower's
///    take-off, legs, return and landing through the PositionController; touch-down (FLIGHT_STATE
///    landed, the vehicle's contact switch) during the landing ends it;
///  - `failsafe`: entered from `flying` when POSE is older than `pose_timeout_s` or the trace of its
///    position covariance exceeds `max_position_cov_trace_m2` (each entry counts one failsafe event).
///    It holds the attitude level and
///    descends with `failsafe_descent_acc_m_s2` less than the learnt hover thrust. A POSE healthy for
///    `recover_after_s` resumes the interrupted leg from the estimated position; touch-down ends it;
///  - `landed`: motors off, for good.

#include <functional>
#include <optional>
#include <string>

#include "common/types.h"
#include "controller/controller_options.h"
#include "controller/position_controller.h"
#include "controller/waypoint_follower.h"
#include "mission/flight_plan.h"

namespace meshnav::controller {

enum class ControlMode { Idle, Flying, Failsafe, Landed };
const char* toString(ControlMode m);

/// CONTROL_STATUS: what the controller does and why.
struct ControlStatus {
  Timestamp t;                          ///< instant of the update it describes
  ControlMode mode = ControlMode::Idle;
  std::string phase;                    ///< follower phase while flying: takeoff|waypoints|return|landing (spinup)
  int waypoint = -1;                    ///< waypoint the current leg goes to (−1: take-off)
  std::string failsafe_reason;          ///< why the last failsafe began ("" if none)
  int64_t failsafe_events = 0;          ///< failsafe entries so far
  double pose_age_s = -1.0;             ///< now − newest POSE time (−1: none yet) [s]
  double position_cov_trace_m2 = 0.0;   ///< trace of the newest POSE's position covariance [m²]
  Setpoint setpoint;                    ///< the reference while flying
  ControlCommand command;               ///< what was commanded
  bool mission_complete = false;        ///< landed after the whole plan
};

struct ControllerSinks {
  std::function<void(const ControlStatus&)> status;  ///< at `status_rate_hz`
};

class ControllerNode {
 public:
  ControllerNode(const ControllerOptions& options, mission::FlightPlan plan, ControllerSinks sinks = {},
                 double status_rate_hz = 10.0);

  /// The newest POSE (an older one than the newest is ignored).
  void onPose(const PoseEstimate& pose);
  /// The vehicle's contact switch (FLIGHT_STATE).
  void onFlightState(const FlightStateSample& fs);
  /// One control step at `now`: the command for the vehicle.
  ControlCommand update(Timestamp now);

  ControlMode mode() const { return mode_; }
  const ControlStatus& status() const { return status_; }
  const PositionController& positionController() const { return pc_; }

 private:
  /// Empty when POSE is healthy at `now`, else the reason.
  std::string poseProblem(Timestamp now) const;

  ControllerOptions options_;
  WaypointFollower follower_;
  PositionController pc_;
  ControllerSinks sinks_;
  double status_period_s_;
  ControlMode mode_ = ControlMode::Idle;
  std::optional<PoseEstimate> pose_;
  bool landed_flag_ = true;
  std::optional<Timestamp> t0_, last_update_, last_status_, takeoff_begin_, healthy_since_;
  bool follower_started_ = false;
  double failsafe_yaw_rad_ = 0.0;
  /// The attitude the loops use: the newest POSE's, carried on with the commanded rates since.
  Eigen::Matrix3d attitude_R_ = Eigen::Matrix3d::Identity();
  std::optional<Timestamp> attitude_from_;  ///< time of the POSE attitude_R_ started from
  ControlCommand last_cmd_;
  ControlStatus status_;
};

}  // namespace meshnav::controller
