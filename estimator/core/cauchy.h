#pragma once
/// @file cauchy.h
/// @brief Cauchy (Lorentzian) loss of a normalized residual e = r/σ, for the multi-start search
/// of the static range fit (StaticInitializer): ρ(e) = c² ln(1 + e²/c²) ≈ e² near zero, growing
/// only logarithmically beyond c, so a gross outlier's pull on the minimum *vanishes* (its IRLS
/// weight 1/(1 + e²/c²) → 0) instead of staying constant as under Huber. Under Huber a few NLOS
/// ranges of 10–20 σ decide *which* of two nearly equal minima wins and by how much, so a
/// geometry that the inliers leave ambiguous is not seen as such (seed-6 run199 of the robustness
/// sweep: a hover under four nearly collinear ceiling anchors, 6 outliers among 32 ranges; the
/// Huber fit has one minimum 1.5 m and 40° from the truth, the Cauchy fit two headings 69° apart
/// within Δχ² 1, refused). Costs are in χ² units like huber::cost.

#include <cmath>

namespace meshnav::estimator::cauchy {

constexpr double kScale = 2.0;  ///< c [σ]

/// ρ(e) = c² ln(1 + e²/c²).
inline double cost(double e) { return kScale * kScale * std::log1p(e * e / (kScale * kScale)); }

/// IRLS weight ρ'(e) / (2e) = 1 / (1 + e²/c²).
inline double weight(double e) { return 1.0 / (1.0 + e * e / (kScale * kScale)); }

}  // namespace meshnav::estimator::cauchy
