#pragma once
/// @file node_internals.h
/// @brief Helpers shared by the two translation units of EstimatorNode (estimator_node.cpp: input
/// handling, processing and outputs; estimator_node_robustness.cpp: alignment, health, recovery,
/// IMU gaps). Internal to the node.

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <utility>

#include "estimator/core/estimator_options.h"
#include "estimator/node/motion_aligner.h"

namespace meshnav::estimator::node_internal {

inline MotionAlignerOptions alignerOptions(const EstimatorOptions& o) {
  MotionAlignerOptions a;
  a.window_s = o.init.motion_window_s;
  a.min_span_s = o.init.motion_min_span_s;
  a.min_ranges = o.init.motion_min_ranges;
  a.max_sigma_yaw_deg = o.init.motion_max_sigma_yaw_deg;
  a.max_sigma_p_m = o.init.motion_max_sigma_p_m;
  a.sigma_bias_acc_m_s2 = o.init.sigma_bias_acc_m_s2;
  a.sigma_bias_gyro_rad_s = o.init.sigma_bias_gyro_rad_s;
  a.outlier_m = o.init.range_init_outlier_m;
  a.ambiguity_chi2 = o.init.ambiguity_chi2;
  a.gravity_m_s2 = o.gravity_m_s2;
  a.max_imu_gap_s = o.imu.max_dt_s;
  return a;
}

/// Largest principal position σ [m] and its direction (G).
inline std::pair<double, Eigen::Vector3d> weakestPositionAxis(const Eigen::Matrix3d& P) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(0.5 * (P + P.transpose()));
  return {std::sqrt(std::max(es.eigenvalues()(2), 0.0)), es.eigenvectors().col(2)};
}

}  // namespace meshnav::estimator::node_internal
