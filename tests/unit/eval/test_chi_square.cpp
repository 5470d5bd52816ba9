#include <gtest/gtest.h>

#include <cmath>

#include "eval/chi_square.h"

using namespace meshnav;
using namespace meshnav::eval;

TEST(ChiSquare, CdfOfKnownValues) {
  // χ²(2) has CDF 1 − exp(−x/2).
  for (double x : {0.1, 1.0, 3.0, 10.0}) EXPECT_NEAR(chi2Cdf(x, 2.0), 1.0 - std::exp(-x / 2.0), 1e-12);
  // χ²(1) CDF = erf(√(x/2)).
  for (double x : {0.5, 2.0, 7.0}) EXPECT_NEAR(chi2Cdf(x, 1.0), std::erf(std::sqrt(x / 2.0)), 1e-12);
  EXPECT_EQ(chi2Cdf(0.0, 3.0), 0.0);
}

TEST(ChiSquare, QuantilesMatchTables) {
  EXPECT_NEAR(chi2Quantile(1, 0.95), 3.841459, 1e-5);
  EXPECT_NEAR(chi2Quantile(3, 0.025), 0.215795, 1e-5);
  EXPECT_NEAR(chi2Quantile(3, 0.975), 9.348404, 1e-5);
  EXPECT_NEAR(chi2Quantile(3, 0.997), 13.93, 0.005);  // the paper's 99.7 % threshold
  EXPECT_NEAR(chi2Quantile(100, 0.025), 74.2219, 1e-3);
  EXPECT_NEAR(chi2Quantile(100, 0.975), 129.5612, 1e-3);
}

TEST(ChiSquare, QuantileInvertsCdfForLargeDof) {
  for (double dof : {3.0, 300.0, 3.0e4, 3.0e5}) {
    for (double p : {0.025, 0.5, 0.975}) {
      const double x = chi2Quantile(dof, p);
      EXPECT_NEAR(chi2Cdf(x, dof), p, 1e-9) << "dof " << dof;
    }
  }
}

TEST(ChiSquare, AneesBoundsShrinkAroundDof) {
  const auto b1 = aneesBounds(1, 3);
  EXPECT_NEAR(b1.lower, 0.215795, 1e-5);
  EXPECT_NEAR(b1.upper, 9.348404, 1e-5);
  const auto b = aneesBounds(1000, 3);
  EXPECT_LT(b.lower, 3.0);
  EXPECT_GT(b.upper, 3.0);
  EXPECT_NEAR(b.upper - b.lower, 2 * 1.96 * std::sqrt(6.0 / 1000.0), 0.01);  // normal approximation
  EXPECT_TRUE(b.contains(3.0));
  EXPECT_FALSE(b.contains(3.5));
  EXPECT_TRUE(std::isnan(aneesBounds(0, 3).lower));
}

TEST(ChiSquare, BadArgumentsAreRefused) {
  EXPECT_THROW(chi2Quantile(0.0, 0.5), std::invalid_argument);
  EXPECT_THROW(chi2Quantile(3.0, 1.0), std::invalid_argument);
  EXPECT_THROW(chi2Cdf(-1.0, 3.0), std::invalid_argument);
}
