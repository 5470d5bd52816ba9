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
/// The filter's update is the mixture's posterior collapsed to one Gaussian (`collapse`, assumed-density
/// filtering: the line-of-sight update and the NLOS one given the excess's posterior, moment-matched).
/// A negative or small innovation keeps w ≈ 1 and the plain update; a positive one of a few tenths
/// of a metre, where the NLOS density dominates, moves the state by little and shrinks its
/// covariance by little.
/// The whole-recording smoother weighs each range by w in its EM passes (`innovationInflation`, 1/w
/// floored at kMinWeight).

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

/// The NLOS excess given the innovation: under NLOS r − b ~ N(0, s) and b − b₀ ~ Exp(1/λ), so
/// p(b | r) ∝ exp(−(r − b)²/(2s) − λ b) on b ≥ b₀: N(m, s), m = r − λ s, truncated below at b₀.
/// With α = (b₀ − m)/√s and the inverse Mills ratio ρ = φ(α)/(1 − Φ(α)):
///     E[b | r] = m + √s ρ,   Var[b | r] = s (1 + α ρ − ρ²).
struct ExcessMoments {
  double mean_m = 0.0;
  double var_m2 = 0.0;
};
inline ExcessMoments excessGivenInnovation(double r, double s, double b0_m, double mean_m) {
  const double lambda = 1.0 / mean_m, sd = std::sqrt(s), m = r - lambda * s;
  const double alpha = (b0_m - m) / sd;
  double rho;  // φ(α)/(1 − Φ(α))
  if (alpha < 30.0) {
    rho = std::exp(-0.5 * alpha * alpha) / std::sqrt(2.0 * M_PI) / (0.5 * std::erfc(alpha / std::sqrt(2.0)));
  } else {  // the tail's asymptotic series (the quotient underflows)
    const double a2 = alpha * alpha;
    rho = alpha + 1.0 / alpha - 2.0 / (alpha * a2);
  }
  ExcessMoments out;
  out.mean_m = std::max(b0_m, m + sd * rho);
  out.var_m2 = std::clamp(s * (1.0 + alpha * rho - rho * rho), 0.0, s);
  return out;
}

/// One range's update under the mixture, collapsed to one Gaussian (assumed-density filtering):
/// the line-of-sight component gives x̂ + K r, P − K s Kᵀ; the NLOS one, given b, the update of
/// r − b, so over b | r: x̂ + K (r − E b), P − K s Kᵀ + K Var b Kᵀ (K = P Hᵀ / s). Their moments
/// with weights w and 1 − w:
///     x̂⁺ = x̂ + K (r − (1 − w) E b),
///     P⁺ = P − K (s − c) Kᵀ,   c = (1 − w) Var b + w (1 − w) (E b)²,
/// c the NLOS branch's own spread and the spread between the two branches' means.
struct MixtureStep {
  double w = 1.0;         ///< posterior probability of line of sight
  double residual = 0.0;  ///< r − (1 − w) E[b | r] [m]
  double spread_m2 = 0.0; ///< c [m²]
};
inline MixtureStep collapse(double r, double s, double eps, double b0_m, double mean_m) {
  MixtureStep out;
  out.w = losProbability(r, s, eps, b0_m, mean_m);
  out.residual = r;
  if (out.w >= 1.0) return out;
  const ExcessMoments b = excessGivenInnovation(r, s, b0_m, mean_m);
  out.residual = r - (1.0 - out.w) * b.mean_m;
  out.spread_m2 = (1.0 - out.w) * b.var_m2 + out.w * (1.0 - out.w) * b.mean_m * b.mean_m;
  return out;
}

}  // namespace meshnav::estimator::nlos
