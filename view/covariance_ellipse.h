#pragma once
/// @file covariance_ellipse.h
/// @brief The horizontal (x–y) uncertainty ellipse of a 3-D position covariance, for the top view.
///
/// With P the 2×2 upper-left block of a position covariance in G, P = V diag(λ₁, λ₂) Vᵀ
/// (λ₁ ≥ λ₂ ≥ 0), the ellipse { p : (p − μ)ᵀ P⁻¹ (p − μ) ≤ k² } has semi-axes a = k √λ₁,
/// b = k √λ₂, the major one along V's first column at angle θ = atan2(v₁y, v₁x) from the x axis
/// of G. k² = χ²₂(0.95) = 5.991 gives the 95 % region of a Gaussian (kChi2Scale95).

#include <Eigen/Core>

namespace meshnav::view {

/// k = √χ²₂(0.95): the scale of the 95 % ellipse of a 2-D Gaussian [-].
inline constexpr double kChi2Scale95 = 2.447746830680816;

struct Ellipse2d {
  double a_m = 0.0;        ///< semi-major axis [m]
  double b_m = 0.0;        ///< semi-minor axis [m]
  double angle_rad = 0.0;  ///< major axis from +x of G towards +y, in (−π/2, π/2] [rad]
};

/// The ellipse of the x–y block of `cov_m2` (3×3, G) scaled by `k`. A non-finite block, or one
/// with a negative eigenvalue beyond rounding, gives the λ clamped at 0 (never NaN).
Ellipse2d horizontalEllipse(const Eigen::Matrix3d& cov_m2, double k = kChi2Scale95);

}  // namespace meshnav::view
