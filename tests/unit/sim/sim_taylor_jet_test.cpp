#include <gtest/gtest.h>

#include <cmath>

#include "sim/taylor_jet.h"

using meshnav::sim::TaylorJet;

// f(t) = sin(t²) / sqrt(1 + t): compare the jet's derivatives with central differences of the
// value, and the first derivative with the analytic one.
TEST(SimTaylorJet, DerivativesMatchFiniteDifferences) {
  auto f = [](double t) { return std::sin(t * t) / std::sqrt(1.0 + t); };
  auto jet = [](double t) {
    const auto x = TaylorJet<4>::variable(t);
    return sin(x * x) / sqrt(1.0 + x);
  };
  for (double t : {0.3, 1.1, 2.7}) {
    const auto j = jet(t);
    const double h = 1e-3;
    EXPECT_NEAR(j.derivative(0), f(t), 1e-15);
    const double d1 = (f(t + h) - f(t - h)) / (2 * h);
    const double d2 = (f(t + h) - 2 * f(t) + f(t - h)) / (h * h);
    EXPECT_NEAR(j.derivative(1), d1, 1e-5);
    EXPECT_NEAR(j.derivative(2), d2, 1e-4);
    // Third/fourth derivatives: differences of the jet's own lower derivatives.
    EXPECT_NEAR(j.derivative(3), (jet(t + h).derivative(2) - jet(t - h).derivative(2)) / (2 * h), 1e-3);
    EXPECT_NEAR(j.derivative(4), (jet(t + h).derivative(3) - jet(t - h).derivative(3)) / (2 * h), 1e-2);
    const double analytic_d1 = 2 * t * std::cos(t * t) / std::sqrt(1 + t) - 0.5 * std::sin(t * t) / std::pow(1 + t, 1.5);
    EXPECT_NEAR(j.derivative(1), analytic_d1, 1e-12);
  }
}

TEST(SimTaylorJet, DerivedShiftsTheCoefficients) {
  // p(t) = t⁴ at t = 2: p'' = 12 t² = 48, p''' = 24 t = 48, p'''' = 24.
  const auto t = TaylorJet<4>::variable(2.0);
  const auto p = t * t * t * t;
  const auto a = p.derived<2>();
  EXPECT_DOUBLE_EQ(a.derivative(0), 48.0);
  EXPECT_DOUBLE_EQ(a.derivative(1), 48.0);
  EXPECT_DOUBLE_EQ(a.derivative(2), 24.0);
}

TEST(SimTaylorJet, Atan2MatchesTheAnalyticDerivativesInEveryQuadrant) {
  // h(t) = atan2(sin(ωt + φ), cos(ωt + φ)) = ωt + φ (mod 2π): h′ = ω, higher derivatives zero;
  // and for the ellipse y = b sin t, x = a cos t: h′ = ab / (a² cos² t + b² sin² t).
  const double w = 1.7, a = 2.0, b = 0.5;
  for (double t0 : {0.3, 1.9, 3.5, 5.2}) {
    const TaylorJet<4> t = TaylorJet<4>::variable(t0);
    const TaylorJet<4> h = atan2(sin(w * t + 0.4), cos(w * t + 0.4));
    EXPECT_NEAR(std::remainder(h.value() - (w * t0 + 0.4), 2.0 * M_PI), 0.0, 1e-12);
    EXPECT_NEAR(h.derivative(1), w, 1e-12);
    for (int k = 2; k <= 4; ++k) EXPECT_NEAR(h.derivative(k), 0.0, 1e-10) << "k " << k;
    const TaylorJet<4> e = atan2(b * sin(t), a * cos(t));
    const double c = std::cos(t0), s = std::sin(t0);
    EXPECT_NEAR(e.derivative(1), a * b / (a * a * c * c + b * b * s * s), 1e-12);
    // Second derivative: d/dt of ab / D with D = a²c² + b²s², D′ = 2(b² − a²) s c.
    const double D = a * a * c * c + b * b * s * s;
    EXPECT_NEAR(e.derivative(2), -a * b * 2.0 * (b * b - a * a) * s * c / (D * D), 1e-12);
  }
}
