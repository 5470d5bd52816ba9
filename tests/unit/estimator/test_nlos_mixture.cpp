/// nlos_mixture.h (estimator/core): the posterior weight, the excess given the innovation, the
/// collapsed update against the exact posterior; and the step a Linearization takes from them.
#include <gtest/gtest.h>

#include <cmath>

#include "estimator/core/linearization.h"
#include "estimator/core/nlos_mixture.h"

using namespace meshnav::estimator;

TEST(NlosMixture, PositiveInnovationsOfAFewTenthsAreNlosNegativeOnesAreNot) {
  const double s = 0.1 * 0.1, eps = 0.05, b0 = 0.2, mu = 0.3;
  EXPECT_GT(nlos::losProbability(0.0, s, eps, b0, mu), 0.95);
  EXPECT_GT(nlos::losProbability(-0.25, s, eps, b0, mu), 0.99) << "2.5 σ short: no NLOS path makes a range short";
  EXPECT_LT(nlos::losProbability(0.25, s, eps, b0, mu), 0.7) << "2.5 σ long: a third NLOS";
  EXPECT_LT(nlos::losProbability(0.35, s, eps, b0, mu), 0.1) << "3.5 σ long: most likely an excess";
  // Monotone over the positive side, symmetric neither way.
  double prev = 1.0;
  for (double r = 0.0; r <= 0.6; r += 0.05) {
    const double w = nlos::losProbability(r, s, eps, b0, mu);
    EXPECT_LE(w, prev + 1e-12) << r;
    prev = w;
  }
  // Off, or nothing to weigh: 1.
  EXPECT_DOUBLE_EQ(nlos::losProbability(0.3, s, 0.0, b0, mu), 1.0);
  EXPECT_DOUBLE_EQ(nlos::losProbability(NAN, s, eps, b0, mu), 1.0);
  // Far out on either side no overflow: the floor on w bounds the inflation.
  EXPECT_DOUBLE_EQ(nlos::innovationInflation(50.0, s, eps, b0, mu), 1.0 / nlos::kMinWeight);
  EXPECT_NEAR(nlos::innovationInflation(-50.0, s, eps, b0, mu), 1.0, 1e-12);
  // A state that is itself uncertain (s large) explains a long range as its own error.
  EXPECT_GT(nlos::losProbability(0.25, 0.5 * 0.5, eps, b0, mu), 0.9);
}

TEST(NlosMixture, TheWeightIsTheBayesPosteriorOfTheTwoDensities) {
  // w = (1 − ε) N(r; 0, s) / ((1 − ε) N + ε p_N), p_N the density of N(0, s) + b₀ + Exp(μ),
  // checked against a numerical convolution.
  const double s = 0.12 * 0.12, eps = 0.05, b0 = 0.2, mu = 0.3;
  for (double r : {-0.1, 0.1, 0.2, 0.35, 0.6}) {
    double p_n = 0.0;
    const double db = 1e-4;
    for (double b = 0.0; b < 6.0; b += db)
      p_n += std::exp(-b / mu) / mu * std::exp(-0.5 * (r - b0 - b) * (r - b0 - b) / s) / std::sqrt(2 * M_PI * s) * db;
    const double p_l = std::exp(-0.5 * r * r / s) / std::sqrt(2 * M_PI * s);
    const double w = (1 - eps) * p_l / ((1 - eps) * p_l + eps * p_n);
    EXPECT_NEAR(nlos::losProbability(r, s, eps, b0, mu), w, 1e-3) << r;
  }
}

namespace {

/// Numerical posterior of a scalar state x ~ N(0, p) from z = x + v + [NLOS] b, v ~ N(0, R),
/// b = b₀ + Exp(μ) with probability ε: mean and variance by quadrature over x and b.
struct Moments {
  double mean, var;
};
Moments numericalPosterior(double z, double p, double R, double eps, double b0, double mu) {
  double m0 = 0.0, m1 = 0.0, m2 = 0.0;
  const double dx = 2e-3, db = 2e-3;
  for (double x = -8.0 * std::sqrt(p); x <= 8.0 * std::sqrt(p); x += dx) {
    const double prior = std::exp(-0.5 * x * x / p);
    const double los = std::exp(-0.5 * (z - x) * (z - x) / R) / std::sqrt(2 * M_PI * R);
    double nlos = 0.0;
    for (double b = 0.0; b < 4.0; b += db) {
      const double e = z - x - b0 - b;
      nlos += std::exp(-b / mu) / mu * std::exp(-0.5 * e * e / R) / std::sqrt(2 * M_PI * R) * db;
    }
    const double w = prior * ((1 - eps) * los + eps * nlos);
    m0 += w;
    m1 += w * x;
    m2 += w * x * x;
  }
  const double mean = m1 / m0;
  return {mean, m2 / m0 - mean * mean};
}

}  // namespace

TEST(NlosMixture, TheExcessGivenTheInnovationIsATruncatedNormal) {
  // b | r ∝ N(r − b; 0, s) λ e^{−λ(b − b₀)} on b ≥ b₀, by quadrature.
  const double s = 0.12 * 0.12, b0 = 0.2, mu = 0.3;
  for (double r : {-0.3, 0.0, 0.2, 0.45, 1.2}) {
    double m0 = 0.0, m1 = 0.0, m2 = 0.0;
    for (double b = b0; b < b0 + 8.0; b += 1e-4) {
      const double w = std::exp(-0.5 * (r - b) * (r - b) / s - (b - b0) / mu);
      m0 += w;
      m1 += w * b;
      m2 += w * b * b;
    }
    const double mean = m1 / m0, var = m2 / m0 - mean * mean;
    const nlos::ExcessMoments e = nlos::excessGivenInnovation(r, s, b0, mu);
    EXPECT_NEAR(e.mean_m, mean, 1e-4) << r;
    EXPECT_NEAR(e.var_m2, var, 1e-5) << r;
  }
  // Far below b₀ (the tail's asymptotic series): b sits just above b₀, E b − b₀ → s/(b₀ − m) with
  // m = r − s/μ, and its variance vanishes.
  const nlos::ExcessMoments far = nlos::excessGivenInnovation(-5.0, s, b0, mu);
  EXPECT_NEAR(far.mean_m - b0, s / (b0 - (-5.0 - s / mu)), 1e-5);
  EXPECT_LT(far.var_m2, 1e-5);
  EXPECT_GE(far.var_m2, 0.0);
}

TEST(NlosMixture, TheCollapseHasTheMomentsOfTheExactPosterior) {
  // A scalar state observed directly (H = 1): the collapsed update x̂ + K r', p − K (s − c) K is the
  // exact posterior's mean and variance, which is what moment matching promises.
  const double p = 0.2 * 0.2, R = 0.12 * 0.12, s = p + R, eps = 0.1, b0 = 0.2, mu = 0.3, K = p / s;
  for (double z : {-0.3, 0.05, 0.25, 0.4, 0.7, 1.5}) {
    const nlos::MixtureStep m = nlos::collapse(z, s, eps, b0, mu);
    const Moments exact = numericalPosterior(z, p, R, eps, b0, mu);
    EXPECT_NEAR(K * m.residual, exact.mean, 2e-4) << z;
    EXPECT_NEAR(p - K * (s - m.spread_m2) * K, exact.var, 2e-4) << z;
  }
  // ε = 0: the plain update.
  const nlos::MixtureStep off = nlos::collapse(0.7, s, 0.0, b0, mu);
  EXPECT_DOUBLE_EQ(off.residual, 0.7);
  EXPECT_DOUBLE_EQ(off.spread_m2, 0.0);
}

TEST(NlosMixture, ALinearizationAppliesTheMixtureOnlyWhileTheMeasurementDominates) {
  Linearization lin;
  lin.residual = Eigen::VectorXd::Constant(1, 0.35);
  lin.R = Eigen::MatrixXd::Constant(1, 1, 0.01);
  const double s = 0.015;  // H P Hᵀ = R/2
  Linearization::ScalarStep plain = lin.scalarStep(s, 0.35 * 0.35 / s);
  EXPECT_DOUBLE_EQ(plain.residual, 0.35) << "ε = 0: the plain update";
  EXPECT_DOUBLE_EQ(plain.spread_m2, 0.0);
  EXPECT_DOUBLE_EQ(plain.s_step, s);
  lin.nlos_fraction = 0.05;
  const Linearization::ScalarStep mixed = lin.scalarStep(s, 0.35 * 0.35 / s);
  const nlos::MixtureStep m = nlos::collapse(0.35, s, 0.05, 0.2, 0.3);
  EXPECT_DOUBLE_EQ(mixed.residual, m.residual);
  EXPECT_DOUBLE_EQ(mixed.spread_m2, m.spread_m2);
  EXPECT_LT(mixed.residual, 0.2) << "a 2.9 σ long range moves the state by less than half";
  EXPECT_GT(mixed.spread_m2, 0.0);
  // H P Hᵀ = 3 R: the innovation is more likely the state's own error; corrected in full.
  const Linearization::ScalarStep state = lin.scalarStep(0.04, 0.35 * 0.35 / 0.04);
  EXPECT_DOUBLE_EQ(state.residual, 0.35);
  EXPECT_DOUBLE_EQ(state.spread_m2, 0.0);
}
