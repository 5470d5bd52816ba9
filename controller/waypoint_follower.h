#pragma once
/// @file waypoint_follower.h
/// @brief Setpoints along a flight plan (mission/flight_plan.h): the take-off straight up to
/// `takeoff_height`, straight legs to every waypoint (with its hold), a leg back above the pad,
/// then the landing (descent at `vertical_speed` until touch-down, `Setpoint::hold_z` false).
///
/// A leg from A to B of length L runs a trapezoidal speed profile with cruise speed V (the plan's
/// speed, lowered so that the vertical part stays within `vertical_speed`) and ramps of
/// acceleration a: s(τ) = ½ a τ² up to V, then V τ − V²/2a, and symmetrically down (a triangle
/// when L < V²/a); p = A + s(τ) u, v = ṡ u, a = s̈ u with u = (B − A)/L. The heading turns linearly
/// from the leg's start yaw to its end yaw, no faster than `yaw_rate_deg`: the leg lasts the
/// longer of the two, then the waypoint's hold.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "controller/setpoint.h"
#include "mission/flight_plan.h"

namespace meshnav::controller {

class WaypointFollower {
 public:
  enum class Phase { TakeOff, Waypoints, ReturnToPad, Landing };

  explicit WaypointFollower(mission::FlightPlan plan);

  /// Starts the take-off at `t_s` from `p_IinG` (the estimated position on the pad) with `yaw_rad`.
  void start(double t_s, const Eigen::Vector3d& p_IinG, double yaw_rad);
  /// Restarts the current leg at `t_s` from `p_IinG` (after a failsafe): the same end point.
  void resumeFrom(double t_s, const Eigen::Vector3d& p_IinG, double yaw_rad);
  /// The setpoint at `t_s` (after `start`); moves on to the next leg when a leg and its hold end.
  Setpoint setpoint(double t_s);

  Phase phase() const;
  bool landing() const { return leg_ >= legs_.size(); }
  /// Index of the waypoint the current leg goes to (−1: take-off, waypoints.size(): back to the pad).
  int waypointIndex() const;
  const mission::FlightPlan& plan() const { return plan_; }
  static const char* toString(Phase p);

 private:
  struct Leg {
    Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
    double yaw_a = 0.0, yaw_b = 0.0;  ///< heading at the ends (yaw_b unwrapped near yaw_a) [rad]
    double hold_s = 0.0;
    int waypoint = -1;
  };
  /// Timing of leg i from its start: the position profile and the whole duration.
  struct Profile {
    double length = 0.0, v_max = 0.0, t_ramp = 0.0, t_move = 0.0, t_total = 0.0;
  };
  Profile profile(const Leg& leg) const;
  void buildLegs(const Eigen::Vector3d& p0, double yaw0);

  mission::FlightPlan plan_;
  std::vector<Leg> legs_;
  size_t leg_ = 0;
  double leg_start_s_ = 0.0;
  Eigen::Vector3d landing_p_ = Eigen::Vector3d::Zero();
  double landing_yaw_ = 0.0;
};

}  // namespace meshnav::controller
