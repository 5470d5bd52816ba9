#pragma once
/// @file reentry_check.h
/// @brief The joint check of the first tag–anchor ranges after an aiding gap (issue 8, docs/robustness.md
/// "Range gaps").
///
/// After a gap the position prior is wide, so a single NLOS range of +1 m passes its own χ² gate
/// (NIS ≈ 3 with 3σ = 1.7 m) and pulls the estimate. The node holds the first ranges after a gap
/// for a moment and asks this check which of them agree. Each held range i carries its innovation
/// ν_i = z_i − h_i(x̂) at its own time, the position row u_iᵀ = ∂h_i/∂p_IinG and its noise R_i. Over
/// the short hold the dead-reckoning error δp is nearly common to all of them:
///   ν_i ≈ u_iᵀ δp + n_i,   δp ~ N(0, P_pp),   n_i ~ N(0, R_i).
/// Leave-one-out: δp is fitted from the prior and every other kept range,
///   A = P_pp⁻¹ + Σ_{j≠i} u_j u_jᵀ / R_j,   δp̂ = A⁻¹ Σ_{j≠i} u_j ν_j / R_j,
/// and range i is tested with d_i = (ν_i − u_iᵀ δp̂)² / (u_iᵀ A⁻¹ u_i + R_i) against χ²₁(p). The
/// worst range beyond the gate is rejected and the test repeated, so two outliers among six are
/// found one after the other. With fewer than `min_ranges` ranges or `min_anchors` anchors the
/// others cannot outvote one range: nothing is rejected (`checked` false).

#include <Eigen/Core>

#include <vector>

#include "common/types.h"

namespace meshnav::estimator {

class ReentryCheck {
 public:
  /// One held range, linearized at the state of its own time.
  struct Held {
    double nu_m = 0.0;                           ///< innovation z − h(x̂) [m]
    Eigen::Vector3d u = Eigen::Vector3d::Zero();  ///< ∂h/∂p_IinG (unit vector anchor → tag) [-]
    double R_m2 = 0.0;                           ///< range noise variance [m²]
    SensorId anchor = 0;                         ///< the anchor it ranged to
  };

  struct Result {
    std::vector<bool> accepted;  ///< per held range
    bool checked = false;        ///< enough ranges and anchors to test them against each other
    int rejected = 0;
  };

  /// @param P_pp position covariance of the prior [m²]; @param gate_chi2 χ²₁ threshold [-].
  static Result decide(const std::vector<Held>& held, const Eigen::Matrix3d& P_pp, double gate_chi2, int min_ranges,
                       int min_anchors);
};

}  // namespace meshnav::estimator
