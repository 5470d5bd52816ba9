#pragma once
/// @file trajectory_state.h
/// @brief Kinematic state of the IMU frame I at one instant, exact (analytic derivatives).

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace meshnav::sim {

/// p, v, a of I in G; attitude R_ItoG (v_G = R_ItoG v_I); body rates expressed in I.
struct TrajectoryState {
  double t_s = 0.0;
  Eigen::Vector3d p_IinG = Eigen::Vector3d::Zero();      ///< position [m]
  Eigen::Vector3d v_IinG = Eigen::Vector3d::Zero();      ///< velocity ṗ [m/s]
  Eigen::Vector3d a_IinG = Eigen::Vector3d::Zero();      ///< acceleration p̈ [m/s²]
  Eigen::Matrix3d R_ItoG = Eigen::Matrix3d::Identity();  ///< attitude
  Eigen::Quaterniond q_ItoG = Eigen::Quaterniond::Identity();
  Eigen::Vector3d w_IinI = Eigen::Vector3d::Zero();      ///< ω_I: [ω]× = R_ItoGᵀ Ṙ_ItoG [rad/s]
  Eigen::Vector3d alpha_IinI = Eigen::Vector3d::Zero();  ///< α_I = ω̇_I [rad/s²]
  double yaw_rad = 0.0;                                  ///< commanded heading ψ (x_I projected on the xy plane)
};

}  // namespace meshnav::sim
