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
  /// > 0: Huber-weighted update of a scalar measurement (docs/robustness.md, "Ranges that pass the
  /// gate"; ignored for m > 1): with e = √NIS beyond k, the innovation covariance S is taken as
  /// S·e/k (R grows by S·(e/k − 1)), so the step is k/e of the plain one (the innovation clipped
  /// to k√S) and P shrinks less. The reported
  /// NIS and the gate stay those of the stated R. 0: the plain update. Only while the state's
  /// share of S is small, tr(H P Hᵀ) ≤ huber_max_prior_ratio · tr(R): then a large innovation is
  /// the measurement's; beyond, it is more likely the state's own error, which the update must
  /// correct in full (a filter that has drifted would otherwise never catch up).
  double huber_k = 0.0;
  double huber_max_prior_ratio = 1.0;
  int dim() const { return static_cast<int>(residual.size()); }
  /// The block of instance `id`, or nullptr.
  const JacobianBlock* find(SensorId id) const {
    for (const auto& b : blocks)
      if (b.id == id) return &b;
    return nullptr;
  }
};

}  // namespace meshnav::estimator
