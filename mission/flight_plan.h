#pragma once
/// @file flight_plan.h
/// @brief The flight of a closed-loop mission (issue 37, docs/closed_loop.md): the key `flight:`
/// of a mission file, flown by the controller (controller/waypoint_follower.h).
/// @code
/// flight:
///   pad: [0.5, -1.5]          # take-off and landing point in G (x, y) [m]
///   pad_yaw_deg: 0.0          # heading on the pad [deg]
///   takeoff_at: 8.0           # take-off time after the first sample [s]
///   takeoff_height: 1.0       # climb above the pad to this height (z in G) [m]
///   speed: 0.5                # cruise speed along the legs [m/s]
///   vertical_speed: 0.3       # climb / descent speed on vertical legs and the landing [m/s]
///   acceleration: 0.5         # speed ramps at the ends of every leg [m/s²]
///   yaw_rate_deg: 30.0        # largest heading rate of the setpoint [deg/s]
///   waypoints:                # after the take-off, in order; then back above the pad and land
///     - {p: [1.5, -2.0, 1.0], yaw_deg: 0.0, hold: 0.0}
/// @endcode
/// Every key but `waypoints` is optional (defaults above). Unknown keys and bad values are refused
/// with the file, the line and the key (mission/src/mission.cpp).

#include <Eigen/Core>
#include <vector>

namespace meshnav::mission {

struct Waypoint {
  Eigen::Vector3d p_IinG = Eigen::Vector3d::Zero();  ///< position of the IMU frame in G [m]
  double yaw_deg = 0.0;                              ///< heading at the waypoint [deg]
  double hold_s = 0.0;                               ///< hover there before the next leg [s]
  int line = 0;                                      ///< line in the mission file (0: built in code)
};

struct FlightPlan {
  Eigen::Vector2d pad_xy_m = Eigen::Vector2d::Zero();  ///< take-off and landing point (x, y) in G [m]
  double pad_yaw_deg = 0.0;        ///< heading on the pad [deg]
  double takeoff_at_s = 8.0;       ///< take-off time after the first sample [s]
  double takeoff_height_m = 1.0;   ///< height (z in G) of the take-off's end [m]
  double speed_m_s = 0.5;          ///< cruise speed along the legs [m/s]
  double vertical_speed_m_s = 0.3; ///< climb, descent and landing speed [m/s]
  double acceleration_m_s2 = 0.5;  ///< ramps of the speed at the legs' ends [m/s²]
  double yaw_rate_deg_s = 30.0;    ///< largest heading rate of the setpoint [deg/s]
  std::vector<Waypoint> waypoints; ///< in flying order (at least one)
};

}  // namespace meshnav::mission
