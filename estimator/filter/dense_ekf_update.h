#pragma once
/// @file dense_ekf_update.h
/// @brief The EKF update on a dense covariance over named blocks, shared by every strategy so that
/// `dp` (which stacks the full state) performs exactly the arithmetic of `centralized`, and `dah`
/// the same on the stacked participants only.
///
/// With H zero outside the named blocks: U = P Hᵀ, S = H U + R (symmetrized), NIS = rᵀ S⁻¹ r,
/// K = U S⁻¹, δx = K r, P ← P − K Uᵀ − U Kᵀ + K S Kᵀ (Joseph form, valid for any K) or
/// P ← P − K Uᵀ; then P is symmetrized.

#include <Eigen/Core>

#include "estimator/core/linearization.h"
#include "estimator/core/state_layout.h"

namespace meshnav::estimator {

struct DenseUpdateOutput {
  bool accepted = false;
  double nis = 0.0;
  Eigen::VectorXd dx;  ///< δx in `layout` order (when accepted)
  Eigen::MatrixXd K;   ///< gain n × m (when accepted)
  Eigen::MatrixXd S;   ///< innovation covariance H P Hᵀ + R_eff, m × m (when accepted; R_eff = R unless weighted: Linearization::stepCovariance)
};

/// Updates `P` (laid out as `layout`) in place when the NIS passes `nis_gate` (≤ 0: no gate).
/// Throws std::logic_error when a Jacobian block has the wrong size or names no block of `layout`.
DenseUpdateOutput denseEkfUpdate(Eigen::MatrixXd& P, const StateLayout& layout, const Linearization& lin,
                                 double nis_gate, bool joseph_form);

}  // namespace meshnav::estimator
