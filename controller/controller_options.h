#pragma once
/// @file controller_options.h
/// @brief Gains, limits and failsafe thresholds of the closed-loop controller (controller/README.md,
/// docs/closed_loop.md); loaded from YAML (config/controller.yaml) the one way of
/// common/yaml_options.h, printed with `toString()`.

#include <string>

#include <yaml-cpp/yaml.h>

namespace meshnav::controller {

struct ControllerOptions {
  // Position → velocity (P) [1/s]
  double kp_xy_per_s = 1.2;
  double kp_z_per_s = 1.5;
  // Velocity → acceleration (PI) [1/s], [1/s²]
  double kv_xy_per_s = 2.5;
  double kv_z_per_s = 3.0;
  double ki_xy_per_s2 = 0.5;
  double ki_z_per_s2 = 1.0;
  double integral_limit_m_s2 = 2.0;  ///< |integral term| per axis [m/s²]
  // Attitude → body rates (P) [1/s]
  double k_tilt_per_s = 7.0;
  double k_yaw_per_s = 2.0;
  // Limits
  double max_speed_xy_m_s = 1.5;     ///< velocity command, horizontal [m/s]
  double max_speed_z_m_s = 1.0;      ///< velocity command, vertical [m/s]
  double max_acc_xy_m_s2 = 3.0;      ///< horizontal acceleration command [m/s²]
  double max_tilt_deg = 25.0;        ///< tilt of the thrust direction [deg]
  double max_rate_rad_s = 2.5;       ///< body rate command per axis [rad/s]
  double max_thrust_m_s2 = 18.0;     ///< collective thrust command [m/s²]
  // Failsafe
  double pose_timeout_s = 0.3;       ///< POSE older than this: failsafe [s]
  double max_position_cov_trace_m2 = 0.5;  ///< trace of POSE's position covariance above this: failsafe [m²]
  double recover_after_s = 2.0;      ///< POSE healthy this long: back to the mission [s]
  double failsafe_descent_acc_m_s2 = 0.1;  ///< thrust below the hover thrust in failsafe [m/s²]
                                           ///< (descent ≈ this / drag: 0.33 m/s at 0.3 1/s)
  double spin_up_s = 0.5;            ///< motors at idle before the take-off leg starts [s]

  static ControllerOptions fromYaml(const YAML::Node& node, const std::string& where);
  /// Loads `path` (empty: defaults).
  static ControllerOptions load(const std::string& path);
  /// Throws std::invalid_argument naming the key.
  void validate() const;
  std::string toString() const;
};

}  // namespace meshnav::controller
