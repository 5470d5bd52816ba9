/// nlos::losProbability / innovationInflation (estimator/core/nlos_mixture.h) and the weighted
/// update through Linearization::robustInflation.
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

TEST(NlosMixture, ALinearizationWeighsOnlyWhileTheMeasurementDominates) {
  Linearization lin;
  lin.residual = Eigen::VectorXd::Constant(1, 0.35);
  lin.R = Eigen::MatrixXd::Constant(1, 1, 0.01);
  EXPECT_DOUBLE_EQ(lin.robustInflation(9.0, 0.015), 1.0) << "ε = 0: the plain update";
  lin.nlos_fraction = 0.05;
  const double f = lin.robustInflation(8.2, 0.015);  // H P Hᵀ = R/2
  EXPECT_NEAR(f, nlos::innovationInflation(0.35, 0.015, 0.05, 0.2, 0.3), 1e-12);
  EXPECT_GT(f, 2.0);
  // H P Hᵀ = 3 R: the innovation is more likely the state's own error; corrected in full.
  EXPECT_DOUBLE_EQ(lin.robustInflation(2.25, 0.04), 1.0);
}
