#pragma once
/// @file linearization.h
/// @brief A linearized measurement with Jacobians named per instance (MaRS style):
/// r = z − h(x̂) ≈ Σ_i H_i δx_i + ν, ν ~ N(0, R). A strategy stacks the blocks it holds.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "common/types.h"

namespace meshnav::estimator {

/// ∂r/∂δx_i of one instance i (rows = measurement dimension, cols = instance error dimension).
struct JacobianBlock {
  SensorId id = 0;
  Eigen::MatrixXd H;
};

struct Linearization {
  Eigen::VectorXd residual;        ///< r = z − h(x̂)
  Eigen::MatrixXd R;               ///< measurement noise covariance
  std::vector<JacobianBlock> blocks;
  int dim() const { return static_cast<int>(residual.size()); }
  /// The block of instance `id`, or nullptr.
  const JacobianBlock* find(SensorId id) const {
    for (const auto& b : blocks)
      if (b.id == id) return &b;
    return nullptr;
  }
};

}  // namespace meshnav::estimator
