#pragma once
/// @file huber.h
/// @brief Huber loss of a normalized residual e = r/σ, for the range fits of initialization
/// (StaticInitializer, MotionAligner): quadratic within k, linear beyond, so NLOS outliers do not
/// pick the minimum; and the weight of the filter's optional Huber range update
/// (innovationInflation, Linearization::huber_k). Iteratively reweighted least squares uses
/// weight(e) = ρ'(e) / (2e).

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace meshnav::estimator::huber {

constexpr double kThreshold = 2.0;  ///< k [σ]

/// ρ(e) = e² for |e| ≤ k, 2k|e| − k² beyond.
inline double cost(double e) {
  const double a = std::abs(e);
  return a <= kThreshold ? e * e : 2.0 * kThreshold * a - kThreshold * kThreshold;
}

/// IRLS weight: 1 for |e| ≤ k, k/|e| beyond.
inline double weight(double e) {
  const double a = std::abs(e);
  return a <= kThreshold ? 1.0 : kThreshold / a;
}

/// Factor on the innovation covariance S of a Huber-weighted Kalman update with threshold k
/// (Linearization::huber_k): max(1, √NIS / k); 1 when k ≤ 0 (off), NIS is not finite or the
/// state's share of S, prior_ratio = H P Hᵀ / R, exceeds max_prior_ratio.
inline double innovationInflation(double nis, double k, double prior_ratio, double max_prior_ratio) {
  if (!(k > 0.0) || !std::isfinite(nis) || nis <= k * k || !(prior_ratio <= max_prior_ratio)) return 1.0;
  return std::sqrt(nis) / k;
}

/// Robust variance factor of normalized residuals |e_i| = |r_i|/σ_i: max(1, (1.4826 · median|e|)²),
/// 1 when the ranges fit as well as their stated σ; 1 with fewer than 8 residuals. Used to scale a
/// fit's covariance and its cost margins when the ranges fit worse than σ says.
inline double varianceFactor(std::vector<double> abs_e) {
  if (abs_e.size() < 8) return 1.0;
  auto mid = abs_e.begin() + static_cast<std::ptrdiff_t>(abs_e.size() / 2);
  std::nth_element(abs_e.begin(), mid, abs_e.end());
  const double s = 1.4826 * *mid;
  return std::max(1.0, s * s);
}

}  // namespace meshnav::estimator::huber
