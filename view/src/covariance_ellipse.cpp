/// @file covariance_ellipse.cpp
/// @brief horizontalEllipse (covariance_ellipse.h): closed-form eigen-decomposition of a 2×2
/// symmetric matrix.

#include "view/covariance_ellipse.h"

#include <algorithm>
#include <cmath>

namespace meshnav::view {

Ellipse2d horizontalEllipse(const Eigen::Matrix3d& cov_m2, double k) {
  const double sxx = cov_m2(0, 0);
  const double syy = cov_m2(1, 1);
  const double sxy = 0.5 * (cov_m2(0, 1) + cov_m2(1, 0));  // symmetric part
  if (!std::isfinite(sxx) || !std::isfinite(syy) || !std::isfinite(sxy)) return {};
  // λ = m ± r with m = (sxx + syy)/2, r = √(((sxx − syy)/2)² + sxy²).
  const double m = 0.5 * (sxx + syy);
  const double d = 0.5 * (sxx - syy);
  const double r = std::hypot(d, sxy);
  const double l1 = std::max(0.0, m + r);
  const double l2 = std::max(0.0, m - r);
  Ellipse2d e;
  e.a_m = k * std::sqrt(l1);
  e.b_m = k * std::sqrt(l2);
  // The eigenvector of λ₁ is at θ = ½ atan2(2 sxy, sxx − syy).
  e.angle_rad = r > 0.0 ? 0.5 * std::atan2(2.0 * sxy, sxx - syy) : 0.0;
  return e;
}

}  // namespace meshnav::view
