/// RangeErrorCorrelation (estimator/uwb/range_error_correlation.h): the R inflation of a range from
/// the time since its pair's previous one, (1 + ρ)/(1 − ρ) with ρ = exp(−Δt/τ).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "estimator/uwb/range_error_correlation.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {
Timestamp at(double s) { return Timestamp::fromSec(s); }
}  // namespace

TEST(RangeErrorCorrelation, InflatesByTheFirstOrderFactorOfThePairsInterval) {
  RangeErrorCorrelation c(0.1);
  EXPECT_DOUBLE_EQ(c.inflation(1001, 4, at(10.0)), 1.0) << "no earlier range of the pair";
  c.noteRange(1001, 4, at(10.0));
  const double rho = std::exp(-0.072 / 0.1);
  EXPECT_NEAR(c.inflation(4, 1001, at(10.072)), (1 + rho) / (1 - rho), 1e-9) << "either order of the ids";
  EXPECT_DOUBLE_EQ(c.inflation(1002, 4, at(10.072)), 1.0) << "another pair has its own history";
  EXPECT_NEAR(c.inflation(1001, 4, at(12.0)), 1.0, 1e-8) << "seconds apart: independent";
  EXPECT_DOUBLE_EQ(c.inflation(1001, 4, at(9.0)), 1.0) << "older than the pair's newest range";
  // A repeated range at the same instant carries almost nothing new, without dividing by zero.
  const double same = c.inflation(1001, 4, at(10.0));
  EXPECT_TRUE(std::isfinite(same));
  EXPECT_GT(same, 100.0);
  c.noteRange(1001, 4, at(9.5));  // a late range does not move the pair's newest time back
  EXPECT_NEAR(c.inflation(1001, 4, at(10.072)), (1 + rho) / (1 - rho), 1e-9);
  EXPECT_DOUBLE_EQ(RangeErrorCorrelation(0.0).inflation(1001, 4, at(10.0)), 1.0) << "τ = 0: white";
}

TEST(RangeErrorCorrelation, TheInflatedVarianceOfAMeanMatchesAFirstOrderProcess) {
  // The claim of the model: n samples of an AR(1) error (correlation time τ, sampled every Δt) average
  // to a variance of σ²/n · f, f = (1 + ρ)/(1 − ρ), i.e. n ranges fused with R·f are as informative
  // as the data are. Checked on simulated AR(1) sequences.
  const double tau = 0.1, dt = 0.072, sigma = 0.1, rho = std::exp(-dt / tau);
  RangeErrorCorrelation c(tau);
  c.noteRange(1, 2, at(0.0));
  const double f = c.inflation(1, 2, at(dt));
  std::mt19937 rng(7);
  std::normal_distribution<double> w(0.0, sigma * std::sqrt(1 - rho * rho));
  const int n = 400, runs = 2000;
  double sum_sq = 0.0;
  for (int r = 0; r < runs; ++r) {
    double e = std::normal_distribution<double>(0.0, sigma)(rng), mean = 0.0;
    for (int k = 0; k < n; ++k) {
      mean += e / n;
      e = rho * e + w(rng);
    }
    sum_sq += mean * mean;
  }
  const double var_mean = sum_sq / runs, predicted = sigma * sigma / n * f;
  EXPECT_NEAR(var_mean / predicted, 1.0, 0.1) << "white fusion would claim " << sigma * sigma / n;
  EXPECT_GT(var_mean, 2.0 * sigma * sigma / n) << "f = 2.9 at this rate: far from white";
}
