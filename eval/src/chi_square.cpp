#include "eval/chi_square.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace meshnav::eval {

namespace {

/// Series expansion of P(a, x), converges fast for x < a + 1.
double gammaPSeries(double a, double x) {
  double sum = 1.0 / a;
  double term = sum;
  for (int n = 1; n < 100000; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::abs(term) < std::abs(sum) * 1e-16) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

/// Continued fraction (modified Lentz) of Q(a, x) = 1 − P(a, x), for x ≥ a + 1.
double gammaQContinuedFraction(double a, double x) {
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < 100000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-16) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

}  // namespace

double regularizedGammaP(double a, double x) {
  if (!(a > 0.0) || x < 0.0) throw std::invalid_argument("regularizedGammaP: need a > 0, x >= 0");
  if (x == 0.0) return 0.0;
  if (x < a + 1.0) return gammaPSeries(a, x);
  return 1.0 - gammaQContinuedFraction(a, x);
}

double chiSquareCdf(double x, double dof) {
  if (x <= 0.0) return 0.0;
  return regularizedGammaP(0.5 * dof, 0.5 * x);
}

double chiSquareQuantile(double p, double dof) {
  if (!(p > 0.0 && p < 1.0) || !(dof > 0.0))
    throw std::invalid_argument("chiSquareQuantile: need 0 < p < 1 and dof > 0");
  // Bracket the root: the mean is dof, the std sqrt(2 dof); widen until the CDF brackets p.
  double lo = 0.0;
  double hi = dof + 10.0 * std::sqrt(2.0 * dof) + 10.0;
  while (chiSquareCdf(hi, dof) < p) hi *= 2.0;
  // Bisection is slow but unconditionally robust; 200 halvings reach double precision.
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (chiSquareCdf(mid, dof) < p) lo = mid; else hi = mid;
    if (hi - lo <= 1e-13 * std::max(1.0, hi)) break;
  }
  return 0.5 * (lo + hi);
}

ChiSquareBounds aneesBounds(int n_samples, int dof, double confidence) {
  ChiSquareBounds b;
  if (n_samples <= 0 || dof <= 0) {
    b.lower = b.upper = std::numeric_limits<double>::quiet_NaN();
    return b;
  }
  const double alpha = 1.0 - confidence;
  const double k = static_cast<double>(n_samples) * dof;
  b.lower = chiSquareQuantile(0.5 * alpha, k) / n_samples;
  b.upper = chiSquareQuantile(1.0 - 0.5 * alpha, k) / n_samples;
  return b;
}

}  // namespace meshnav::eval
