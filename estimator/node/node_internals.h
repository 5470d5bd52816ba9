#pragma once
/// @file node_internals.h
/// @brief Helpers shared by the translation units of EstimatorNode (estimator_node.cpp: input
/// handling, processing and outputs; estimator_node_updates.cpp: the measurement updates;
/// estimator_node_robustness.cpp: alignment, health, recovery, IMU gaps). Internal to the node.

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "common/time.h"
#include "estimator/core/estimator_options.h"
#include "estimator/core/imu_state.h"
#include "estimator/init/motion_aligner.h"

namespace meshnav::estimator::node_internal {

/// "CHANNEL t=<seconds>": where a rejected or odd input came from, for messages.
inline std::string where(const char* channel, Timestamp t) { return std::string(channel) + " t=" + formatSeconds(t); }

inline MotionAlignerOptions alignerOptions(const EstimatorOptions& o, const Eigen::Vector3d& p_IH) {
  MotionAlignerOptions a;
  a.p_IH = p_IH;
  a.window_s = o.init.motion_window_s;
  a.min_span_s = o.init.motion_min_span_s;
  a.min_ranges = o.init.motion_min_ranges;
  a.max_sigma_yaw_deg = o.init.motion_max_sigma_yaw_deg;
  a.max_sigma_p_m = o.init.motion_max_sigma_p_m;
  a.relinearize_rad = o.init.motion_relinearize_rad;
  a.sigma_bias_acc_m_s2 = o.init.sigma_bias_acc_m_s2;
  a.sigma_bias_gyro_rad_s = o.init.sigma_bias_gyro_rad_s;
  a.outlier_m = o.init.range_init_outlier_m;
  a.ambiguity_chi2 = o.init.ambiguity_chi2;
  a.gravity_m_s2 = o.gravity_m_s2;
  a.max_imu_gap_s = o.imu.max_dt_s;
  a.max_window_s = o.init.motion_max_window_s;
  a.height_tilt_correction = o.height.tilt_correction;
  a.sigma_bias_height_m = o.height.init_bias_sigma_m;
  return a;
}

/// Largest principal position σ [m] and its direction (G).
inline std::pair<double, Eigen::Vector3d> weakestPositionAxis(const Eigen::Matrix3d& P) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(0.5 * (P + P.transpose()));
  return {std::sqrt(std::max(es.eigenvalues()(2), 0.0)), es.eigenvectors().col(2)};
}

}  // namespace meshnav::estimator::node_internal
