#pragma once
/// @file huber.h
/// @brief Huber loss of a normalized residual e = r/σ, for the range fits of initialization
/// (StaticInitializer, MotionAligner): quadratic within k, linear beyond, so NLOS outliers do not
/// pick the minimum. Iteratively reweighted least squares uses weight(e) = ρ'(e) / (2e).

#include <cmath>

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

}  // namespace meshnav::estimator::huber
