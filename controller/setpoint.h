#pragma once
/// @file setpoint.h
/// @brief What the position controller tracks, and what it commands.

#include <Eigen/Core>

#include "common/time.h"

namespace meshnav::controller {

/// Reference of the IMU frame in G.
struct Setpoint {
  Eigen::Vector3d p_IinG = Eigen::Vector3d::Zero();  ///< position [m]
  Eigen::Vector3d v_IinG = Eigen::Vector3d::Zero();  ///< velocity feed-forward [m/s]
  Eigen::Vector3d a_IinG = Eigen::Vector3d::Zero();  ///< acceleration feed-forward [m/s²]
  double yaw_rad = 0.0;                              ///< heading [rad]
  /// false: the vertical axis follows `v_IinG.z()` only (landing: descend until touch-down).
  bool hold_z = true;
};

/// The vehicle's inner-loop input: mass-normalized collective thrust and body rates.
struct ControlCommand {
  Timestamp t;                                     ///< instant the command was computed for
  double thrust_m_s2 = 0.0;                        ///< collective thrust / mass [m/s²]
  Eigen::Vector3d w_IinI = Eigen::Vector3d::Zero();///< body rates in I [rad/s]
};

}  // namespace meshnav::controller
