#pragma once
/// @file nlos_mixture.h
/// @brief A range's error as a mixture of line of sight and NLOS (issue 34, item 3; derivation in
/// docs/uwb_bias_model.md, "NLOS excess"): the weight of a range that passed the gate.
///
/// With probability 1 − ε the innovation of a range is r ~ N(0, s) (s = H P Hᵀ + R, the state's
/// uncertainty included); with probability ε an NLOS path adds a positive excess b = b₀ + Exp(μ)
/// (real hardware: most of it within a few tenths of a metre, so a χ² gate keeps it). The NLOS
/// density of r is the exponentially modified Gaussian, λ = 1/μ, y = r − b₀:
///
///     p_N(r) = λ exp(λ² s/2 − λ y) Φ((y − λ s)/√s),
///
/// and the posterior probability of line of sight is w = (1 − ε) N(r; 0, s) / ((1 − ε) N(r; 0, s) + ε p_N(r)).
/// The update then takes the range with weight w: s / w as its innovation covariance (R grows by
/// s (1/w − 1)), which is the update of the mixture's line-of-sight component scaled by its
/// posterior. A negative or small innovation keeps w ≈ 1; a positive one of a few tenths of a
/// metre, where the NLOS density dominates, is given little weight. w is floored at kMinWeight.

#include <algorithm>
#include <cmath>

namespace meshnav::estimator::nlos {

constexpr double kMinWeight = 0.01;  ///< floor of w (R grows at most 100-fold)

/// Posterior probability of line of sight of innovation r [m] with variance s [m²].
inline double losProbability(double r, double s, double eps, double b0_m, double mean_m) {
  if (!(eps > 0.0) || !(s > 0.0) || !std::isfinite(r)) return 1.0;
  const double lambda = 1.0 / mean_m, y = r - b0_m, sd = std::sqrt(s);
  const double log_los = std::log1p(-eps) - 0.5 * r * r / s - std::log(sd * std::sqrt(2.0 * M_PI));
  const double x = (y - lambda * s) / sd;                 // argument of Φ
  const double phi = 0.5 * std::erfc(-x / std::sqrt(2.0));  // Φ(x)
  if (!(phi > 0.0)) return 1.0;                           // the NLOS density underflows: line of sight
  const double log_nlos = std::log(eps) + std::log(lambda) + 0.5 * lambda * lambda * s - lambda * y + std::log(phi);
  // w = 1 / (1 + exp(log_nlos − log_los)), without overflow.
  const double d = log_nlos - log_los;
  return d > 50.0 ? 0.0 : 1.0 / (1.0 + std::exp(d));
}

/// Factor on s of the weighted update: 1 / max(w, kMinWeight); 1 when ε = 0.
inline double innovationInflation(double r, double s, double eps, double b0_m, double mean_m) {
  return 1.0 / std::max(losProbability(r, s, eps, b0_m, mean_m), kMinWeight);
}

}  // namespace meshnav::estimator::nlos
