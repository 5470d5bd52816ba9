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

namespace meshnav::estimator::node_internal {

/// "CHANNEL t=<seconds>": where a rejected or odd input came from, for messages.
inline std::string where(const char* channel, Timestamp t) { return std::string(channel) + " t=" + formatSeconds(t); }

/// Largest principal position σ [m] and its direction (G).
inline std::pair<double, Eigen::Vector3d> weakestPositionAxis(const Eigen::Matrix3d& P) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(0.5 * (P + P.transpose()));
  return {std::sqrt(std::max(es.eigenvalues()(2), 0.0)), es.eigenvectors().col(2)};
}

}  // namespace meshnav::estimator::node_internal
