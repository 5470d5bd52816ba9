#include <gtest/gtest.h>

#include <random>

#include "eval/range_statistics.h"

using namespace meshnav;
using namespace meshnav::eval;

namespace {

RangeSample range(double t, SensorId a, UwbType ta, SensorId b, UwbType tb, double z) {
  RangeSample r;
  r.t = Timestamp::fromSec(t);
  r.id_initiator = a;
  r.type_initiator = ta;
  r.id_responder = b;
  r.type_responder = tb;
  r.range_m = z;
  return r;
}

}  // namespace

TEST(EstimateBias, GateMethodIsMeanAndPopulationStd) {
  RangeStatsOptions o;
  o.method = BiasMethod::Gate;
  const auto b = estimateBias({0.1, 0.3, 5.0, -7.0}, o);  // the two gross outliers are gated
  EXPECT_EQ(b.n_in, 4);
  EXPECT_EQ(b.n_used, 2);
  EXPECT_NEAR(b.bias_m, 0.2, 1e-12);
  EXPECT_NEAR(b.std_m, 0.1, 1e-12);
}

TEST(EstimateBias, HistogramMethodRecoversGaussianCoreUnderHeavyTail) {
  std::mt19937 rng(7);
  std::normal_distribution<double> core(0.20, 0.05);
  std::uniform_real_distribution<double> tail(0.3, 0.95);  // one-sided NLOS-like tail
  std::vector<double> e;
  for (int i = 0; i < 4000; ++i) e.push_back(core(rng));
  for (int i = 0; i < 600; ++i) e.push_back(tail(rng));
  for (int i = 0; i < 50; ++i) e.push_back(300.0);  // gross outliers
  RangeStatsOptions o;
  const auto h = estimateBias(e, o);
  o.method = BiasMethod::Gate;
  const auto g = estimateBias(e, o);
  // The gate keeps the tail: biased mean, inflated σ. The histogram filter trims it.
  EXPECT_GT(g.bias_m - 0.20, 0.05);
  EXPECT_NEAR(h.bias_m, 0.20, 0.01);
  EXPECT_NEAR(h.std_m, 0.05, 0.01);
  EXPECT_LT(h.n_used, g.n_used);
}

TEST(EstimateBias, EmptyAndConstantInputs) {
  RangeStatsOptions o;
  EXPECT_TRUE(std::isnan(estimateBias({}, o).bias_m));
  const auto c = estimateBias({0.25, 0.25, 0.25}, o);  // zero histogram width → plain mean
  EXPECT_NEAR(c.bias_m, 0.25, 1e-12);
  EXPECT_NEAR(c.std_m, 0.0, 1e-12);
}

TEST(TrueRangeModel, AnchorToAnchorFromPositions) {
  TrueRangeModel m;
  m.setStaticPositions({{1, {0, 0, 0}}, {2, {3, 4, 0}}});
  EXPECT_NEAR(*m.trueRange(range(0, 1, UwbType::Anchor, 2, UwbType::Anchor, 0)), 5.0, 1e-12);
  TrueRangeMiss miss;
  EXPECT_FALSE(m.trueRange(range(0, 1, UwbType::Anchor, 9, UwbType::Anchor, 0), &miss));
  EXPECT_EQ(miss, TrueRangeMiss::UnknownDevice);
}

TEST(TrueRangeModel, TagOnTrajectoryWithLeverArm) {
  TrueRangeModel m;
  m.setStaticPositions({{101, {0, 0, 0}}});
  // IMU at x = t, yawed 90°: lever arm (1, 0, 0) in I points along +y in G.
  const Eigen::Quaterniond q(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  m.setTrajectory({{Timestamp::fromSec(0), {0, 0, 0}, q}, {Timestamp::fromSec(2), {2, 0, 0}, q}},
                  {{100, {1, 0, 0}}});
  m.setMaxTrajectoryGap(3.0);
  // At t = 1: p_I = (1, 0, 0), tag at (1, 1, 0): distance √2, either direction of the range.
  EXPECT_NEAR(*m.trueRange(range(1.0, 100, UwbType::Tag, 101, UwbType::Anchor, 0)), std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(*m.trueRange(range(1.0, 101, UwbType::Anchor, 100, UwbType::Tag, 0)), std::sqrt(2.0), 1e-12);
  TrueRangeMiss miss;
  EXPECT_FALSE(m.trueRange(range(5.0, 100, UwbType::Tag, 101, UwbType::Anchor, 0), &miss));
  EXPECT_EQ(miss, TrueRangeMiss::TimeGap);
}

TEST(TrueRangeModel, NearestPublishedTrueRangeWithinMaxDt) {
  TrueRangeModel m;
  m.setStaticPositions({{1, {0, 0, 0}}});
  m.setTrueRangeSamples({range(10.00, 0, UwbType::Tag, 1, UwbType::Anchor, 4.0),
                         range(10.03, 0, UwbType::Tag, 1, UwbType::Anchor, 4.3)});
  m.setMaxDt(0.02);
  EXPECT_NEAR(*m.trueRange(range(10.01, 1, UwbType::Anchor, 0, UwbType::Tag, 0)), 4.0, 1e-12);
  EXPECT_NEAR(*m.trueRange(range(10.02, 0, UwbType::Tag, 1, UwbType::Anchor, 0)), 4.3, 1e-12);
  EXPECT_FALSE(m.trueRange(range(10.06, 0, UwbType::Tag, 1, UwbType::Anchor, 0)));
  EXPECT_FALSE(m.trueRange(range(9.90, 0, UwbType::Tag, 1, UwbType::Anchor, 0)));
}

TEST(RangeStatistics, RecoversSimulatedBiasAndNoisePerOrderedPair) {
  // Simulated like the project's sim: z = β d + γ + ν with γ = +0.3 m (1→2), −0.1 m (2→1).
  TrueRangeModel m;
  m.setStaticPositions({{1, {0, 0, 0}}, {2, {6, 0, 0}}});
  std::mt19937 rng(3);
  std::normal_distribution<double> n12(0.0, 0.1), n21(0.0, 0.15);
  std::vector<RangeSample> ranges;
  for (int k = 0; k < 2000; ++k) {
    ranges.push_back(range(k * 0.1, 1, UwbType::Anchor, 2, UwbType::Anchor, 6.0 + 0.3 + n12(rng)));
    ranges.push_back(range(k * 0.1 + 0.05, 2, UwbType::Anchor, 1, UwbType::Anchor, 6.0 - 0.1 + n21(rng)));
  }
  ranges.push_back(range(0.0, 1, UwbType::Anchor, 7, UwbType::Anchor, 3.0));  // unknown device
  Diagnostics diag;
  RangeStatsOptions o;
  o.method = BiasMethod::Gate;
  const auto s = computeRangeStatistics(ranges, m, o, diag);
  ASSERT_EQ(s.size(), 3u);
  // Standard errors: σ/√2000 ≈ 0.003 m for the mean.
  EXPECT_NEAR(s.at({1, 2}).estimate.bias_m, 0.3, 0.012);
  EXPECT_NEAR(s.at({1, 2}).estimate.std_m, 0.1, 0.01);
  EXPECT_NEAR(s.at({2, 1}).estimate.bias_m, -0.1, 0.012);
  EXPECT_NEAR(s.at({2, 1}).estimate.std_m, 0.15, 0.01);
  EXPECT_EQ(s.at({1, 7}).n_with_truth, 0);
  EXPECT_EQ(diag.get("range_stats:no_truth_unknown_device"), 1);
  // The histogram filter trims Gaussian tails too (it keeps the core), so its σ is smaller.
  o.method = BiasMethod::Histogram;
  const auto h = computeRangeStatistics(ranges, m, o, diag);
  EXPECT_NEAR(h.at({1, 2}).estimate.bias_m, 0.3, 0.02);
  EXPECT_LT(h.at({1, 2}).estimate.std_m, 0.1);
}

TEST(EstimateBias, ClipMethodRecoversGaussianSigmaWithOutliers) {
  std::mt19937 rng(11);
  std::normal_distribution<double> core(-0.15, 0.12);
  std::uniform_real_distribution<double> out(-1.0, 1.0);
  std::vector<double> e;
  for (int i = 0; i < 3000; ++i) e.push_back(core(rng));
  for (int i = 0; i < 300; ++i) e.push_back(out(rng) > 0 ? 0.8 : -0.9);  // 10 % outliers
  RangeStatsOptions o;
  o.method = BiasMethod::Clip;
  const auto c = estimateBias(e, o);
  EXPECT_NEAR(c.bias_m, -0.15, 0.01);
  EXPECT_NEAR(c.std_m, 0.12, 0.006);
  EXPECT_LT(c.n_used, 3100);
}

TEST(EstimateBias, HistogramMethodUnderestimatesGaussianSigma) {
  // Documented caveat of the toolbox's filter: on Gaussian errors it keeps only about ±0.9σ.
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.3, 0.1);
  std::vector<double> e;
  for (int i = 0; i < 4000; ++i) e.push_back(g(rng));
  RangeStatsOptions o;
  const auto h = estimateBias(e, o);
  EXPECT_NEAR(h.bias_m, 0.3, 0.01);
  EXPECT_LT(h.std_m, 0.075);
  o.method = BiasMethod::Clip;
  EXPECT_NEAR(estimateBias(e, o).std_m, 0.1, 0.005);
}
