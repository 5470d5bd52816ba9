#pragma once
/// @file estimator_node_testing.h
/// @brief What tests may do to an EstimatorNode that no user may: hold the re-run worker, and put
/// a fault into the pose. Kept out of the node's public interface (a friend of the node).

#include <functional>

#include <Eigen/Core>

#include "estimator/node/estimator_node.h"

namespace meshnav::estimator {

class EstimatorNodeTesting {
 public:
  /// Called on the re-run worker before it starts (a test holds the worker there until it releases
  /// it; the hook must return before the node is destroyed or re-initialized).
  static void setRerunWorkerHook(EstimatorNode& node, std::function<void()> hook) {
    node.rerun_.setWorkerHook(std::move(hook));
  }
  /// Moves the pose estimate by `dp_m` (G) and turns it by `dyaw_rad` about z, keeping its
  /// covariance, as a corrupted state would look to the filter (counted "injected_pose_error").
  static void injectPoseError(EstimatorNode& node, const Eigen::Vector3d& dp_m, double dyaw_rad) {
    node.injectPoseError(dp_m, dyaw_rad);
  }
};

}  // namespace meshnav::estimator
