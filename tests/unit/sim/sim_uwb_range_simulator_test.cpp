#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "sim/paper_scenario.h"
#include "sim/spiral_trajectory.h"
#include "sim/uwb_hardware_biases.h"
#include "sim/uwb_range_simulator.h"

using namespace meshnav::sim;

namespace {
struct Fixture {
  PaperScenario scenario = PaperScenario::paper();
  SpiralTrajectory trajectory{TrajectoryOptions::randomized(4)};
  TdmaSchedule schedule{scenario.uwbDeviceIds(), 0.01, 0.003};
  UwbHardwareBiases biases{scenario.uwbDeviceIds()};
};
}  // namespace

TEST(SimUwbHardwareBiases, SymmetricBoundedAndFixedByHardwareSeed) {
  const PaperScenario sc = PaperScenario::paper();
  const UwbHardwareBiases b(sc.uwbDeviceIds()), b2(sc.uwbDeviceIds());
  const auto all = b.allTrue(0.1);
  EXPECT_EQ(all.size(), 55u);  // 11 choose 2
  double max_gamma = 0;
  for (const auto& p : all) {
    EXPECT_LT(p.a, p.b);
    EXPECT_LE(std::abs(p.gamma_m), 0.4);
    EXPECT_LE(std::abs(p.beta - 1.0), 0.01);
    EXPECT_EQ(b.truth(p.a, p.b).gamma_m, b.truth(p.b, p.a).gamma_m);
    EXPECT_EQ(b2.truth(p.a, p.b).gamma_m, p.gamma_m);  // same modules every time
    max_gamma = std::max(max_gamma, std::abs(p.gamma_m));
    // The a-priori calibration is close to but not equal to the truth.
    const auto c = b.calibrated(p.a, p.b, 0.1);
    EXPECT_NE(c.gamma_m, p.gamma_m);
    EXPECT_LT(std::abs(c.gamma_m - p.gamma_m), 0.1);
    EXPECT_EQ(c.sigma_m, 0.1);
  }
  EXPECT_GT(max_gamma, 0.2);  // biases are significant, as on real hardware
  EXPECT_THROW(b.truth(100, 999), std::out_of_range);
  // A different hardware seed gives different modules.
  UwbHardwareOptions other;
  other.hardware_seed = 7;
  EXPECT_NE(UwbHardwareBiases(sc.uwbDeviceIds(), other).truth(100, 101).gamma_m, b.truth(100, 101).gamma_m);
}

TEST(SimUwbRangeSimulator, NoiseFreeRangesAreBetaTimesDistancePlusGamma) {
  Fixture f;
  UwbRangeOptions opt;
  opt.sigma_range_m = 0.0;
  opt.outlier_fraction = 0.0;
  opt.drop_fraction = 0.0;
  UwbRangeSimulator sim(f.scenario, f.biases, opt, 4);
  const auto ranges = sim.simulate(f.trajectory, f.schedule, 30.0);
  ASSERT_EQ(static_cast<int64_t>(ranges.size()), sim.slotCount());
  for (const auto& r : ranges) {
    const auto st = f.trajectory.evaluate(r.sample.t.sec());
    const double d = (sim.devicePosition(r.sample.id_initiator, st) - sim.devicePosition(r.sample.id_responder, st)).norm();
    const auto& b = f.biases.truth(r.sample.id_initiator, r.sample.id_responder);
    EXPECT_NEAR(r.sample.range_m, b.beta * d + b.gamma_m, 1e-9);
    EXPECT_FALSE(r.outlier);
    EXPECT_EQ(r.sample.type_initiator == meshnav::UwbType::Tag, f.scenario.isTag(r.sample.id_initiator));
    EXPECT_EQ(r.sample.type_responder == meshnav::UwbType::Tag, f.scenario.isTag(r.sample.id_responder));
  }
  // Anchor–anchor ranges are constant; the tag–tag range is the lever-arm distance.
  for (const auto& r : ranges) {
    if (r.sample.id_initiator == 100 && r.sample.id_responder == 105) {
      const double d = (f.scenario.tags_p_TinI.at(100) - f.scenario.tags_p_TinI.at(105)).norm();
      EXPECT_NEAR(r.true_distance_m, d, 1e-12);
    }
    if (r.sample.id_initiator == 101 && r.sample.id_responder == 102) {
      const double d = (f.scenario.anchors_p_AinG.at(101) - f.scenario.anchors_p_AinG.at(102)).norm();
      EXPECT_NEAR(r.true_distance_m, d, 1e-12);
    }
  }
}

TEST(SimUwbRangeSimulator, OutlierAndDropFractionsMatchTheTarget) {
  Fixture f;
  UwbRangeOptions opt;
  opt.sigma_range_m = 0.1;
  opt.outlier_fraction = 0.10;
  opt.drop_fraction = 0.05;
  UwbRangeSimulator sim(f.scenario, f.biases, opt, 8);
  const auto ranges = sim.simulate(f.trajectory, f.schedule, f.trajectory.duration());
  const double n = static_cast<double>(ranges.size());
  ASSERT_GT(n, 10000);
  EXPECT_NEAR(static_cast<double>(sim.droppedCount()) / sim.slotCount(), 0.05, 0.01);
  EXPECT_NEAR(static_cast<double>(sim.outlierCount()) / n, 0.10, 0.01);
  // Residuals: inliers ~ N(0, σ²), outliers positive in [0.5, 3] m (+ noise).
  double s2 = 0, sum_out = 0;
  int n_in = 0, n_out = 0;
  for (const auto& r : ranges) {
    const auto& b = f.biases.truth(r.sample.id_initiator, r.sample.id_responder);
    const double e = r.sample.range_m - (b.beta * r.true_distance_m + b.gamma_m);
    if (r.outlier) {
      // Offset U(0.5, 3) plus noise of σ 0.1: within 5σ of the interval, mean 1.75.
      EXPECT_GT(e, 0.5 - 5 * 0.1);
      EXPECT_LT(e, 3.0 + 5 * 0.1);
      sum_out += e;
      ++n_out;
    } else {
      s2 += e * e;
      ++n_in;
    }
    EXPECT_NEAR(r.sample.R_m2, 0.01, 1e-15);
    EXPECT_EQ(r.sample.range_corr_m, r.sample.range_m);
  }
  EXPECT_NEAR(std::sqrt(s2 / n_in), 0.1, 0.005);
  ASSERT_GT(n_out, 500);
  EXPECT_NEAR(sum_out / n_out, 1.75, 0.1);  // σ of the mean ≈ 0.72/√n_out < 0.03
}

TEST(SimUwbRangeSimulator, NoiseLevelDoesNotChangeWhichRangesAreOutliersOrDropped) {
  Fixture f;
  UwbRangeOptions noisy, quiet;
  quiet.sigma_range_m = 0.0;
  UwbRangeSimulator a(f.scenario, f.biases, noisy, 2), b(f.scenario, f.biases, quiet, 2);
  const auto ra = a.simulate(f.trajectory, f.schedule, 40.0), rb = b.simulate(f.trajectory, f.schedule, 40.0);
  ASSERT_EQ(ra.size(), rb.size());
  for (size_t k = 0; k < ra.size(); ++k) {
    EXPECT_EQ(ra[k].sample.t, rb[k].sample.t);
    EXPECT_EQ(ra[k].outlier, rb[k].outlier);
  }
}

TEST(SimUwbRangeSimulator, ExponentialNlosExcessStartsAtTwentyCentimetresWithItsMean) {
  // Real hardware's NLOS: 0.2 m + Exp(mean 0.3 m), most of it below 1 m; the same slots are
  // outliers as with the paper's U(0.5, 3) m (the same draws).
  Fixture f;
  UwbRangeOptions uni, ex;
  uni.sigma_range_m = ex.sigma_range_m = 0.0;
  uni.outlier_fraction = ex.outlier_fraction = 0.10;
  ex.nlos_excess = "exponential";
  ex.outlier_min_m = 0.2;
  ex.outlier_mean_m = 0.3;
  UwbRangeSimulator a(f.scenario, f.biases, uni, 8), b(f.scenario, f.biases, ex, 8);
  const auto ra = a.simulate(f.trajectory, f.schedule, f.trajectory.duration());
  const auto rb = b.simulate(f.trajectory, f.schedule, f.trajectory.duration());
  ASSERT_EQ(ra.size(), rb.size());
  double sum = 0;
  int n = 0, below_1m = 0;
  for (size_t k = 0; k < rb.size(); ++k) {
    ASSERT_EQ(ra[k].outlier, rb[k].outlier);
    if (!rb[k].outlier) continue;
    const auto& bias = f.biases.truth(rb[k].sample.id_initiator, rb[k].sample.id_responder);
    const double e = rb[k].sample.range_m - (bias.beta * rb[k].true_distance_m + bias.gamma_m);
    EXPECT_GE(e, 0.2 - 1e-9);
    sum += e;
    ++n;
    below_1m += e < 1.0;
  }
  ASSERT_GT(n, 1000);
  EXPECT_NEAR(sum / n, 0.5, 0.03);                          // 0.2 + 0.3
  EXPECT_NEAR(static_cast<double>(below_1m) / n, 1.0 - std::exp(-0.8 / 0.3), 0.03);  // P(Exp < 0.8 m)
}

TEST(SimUwbRangeSimulator, CorrelatedErrorsFollowAFirstOrderProcessPerPair) {
  // Lag-one correlation of a pair's consecutive errors = exp(−Δt/τ) at the pair's interval; the
  // marginal σ stays σ_d; τ = 0 leaves every range as the paper's.
  Fixture f;
  UwbRangeOptions white, corr;
  white.outlier_fraction = corr.outlier_fraction = 0.0;
  white.drop_fraction = corr.drop_fraction = 0.0;
  corr.correlation_time_s = 2.0;
  UwbRangeSimulator a(f.scenario, f.biases, white, 5), b(f.scenario, f.biases, corr, 5);
  const auto ra = a.simulate(f.trajectory, f.schedule, f.trajectory.duration());
  const auto rb = b.simulate(f.trajectory, f.schedule, f.trajectory.duration());
  ASSERT_EQ(ra.size(), rb.size());
  std::map<std::pair<meshnav::SensorId, meshnav::SensorId>, std::pair<double, double>> last;  // t, e
  double sxy = 0, sxx = 0, s2 = 0, dt_sum = 0;
  int n = 0;
  for (const auto& r : rb) {
    const auto& bias = f.biases.truth(r.sample.id_initiator, r.sample.id_responder);
    const double e = (r.sample.range_m - (bias.beta * r.true_distance_m + bias.gamma_m)) / corr.sigma_range_m;
    const auto key = meshnav::pairKey(r.sample.id_initiator, r.sample.id_responder);
    if (auto it = last.find(key); it != last.end()) {
      sxy += it->second.second * e;
      sxx += it->second.second * it->second.second;
      dt_sum += r.sample.t.sec() - it->second.first;
      ++n;
    }
    s2 += e * e;
    last[key] = {r.sample.t.sec(), e};
  }
  ASSERT_GT(n, 5000);
  // The pair's slots are unevenly spaced (both directions of a pair); compare with the mean of ρ
  // loosely: for Δt ≪ τ, ρ ≈ 1 − Δt/τ is linear, so the mean interval gives the mean ρ.
  EXPECT_NEAR(sxy / sxx, std::exp(-(dt_sum / n) / 2.0), 0.03);
  EXPECT_NEAR(std::sqrt(s2 / rb.size()), 1.0, 0.1);
  for (size_t k = 0; k < ra.size(); k += 97) EXPECT_EQ(ra[k].outlier, rb[k].outlier);
}

TEST(SimUwbRangeSimulator, ATimeOffsetStampsTheDistanceAtTWithTPlusTheOffset) {
  // Noise-free: the range stamped s is the distance at s − δ exactly (and, the vehicle moving, not
  // the distance at s); the same slots, draws and values as without the offset, only the stamps
  // move; a stamp that would fall before 0 is not written.
  Fixture f;
  UwbRangeOptions plain, late, early;
  plain.sigma_range_m = late.sigma_range_m = early.sigma_range_m = 0.0;
  late.time_offset_s = 0.05;
  early.time_offset_s = -0.05;
  UwbRangeSimulator a(f.scenario, f.biases, plain, 4), b(f.scenario, f.biases, late, 4), c(f.scenario, f.biases, early, 4);
  const auto ra = a.simulate(f.trajectory, f.schedule, 30.0);
  const auto rb = b.simulate(f.trajectory, f.schedule, 30.0);
  const auto rc = c.simulate(f.trajectory, f.schedule, 30.0);
  ASSERT_EQ(ra.size(), rb.size());
  double moved = 0.0;
  for (size_t k = 0; k < rb.size(); ++k) {
    EXPECT_EQ(rb[k].sample.range_m, ra[k].sample.range_m);
    EXPECT_EQ(rb[k].sample.t.us - ra[k].sample.t.us, 50000);
    if (rb[k].outlier) continue;
    const auto& bias = f.biases.truth(rb[k].sample.id_initiator, rb[k].sample.id_responder);
    const auto at = [&](double t) {
      const auto st = f.trajectory.evaluate(t);
      return bias.beta * (b.devicePosition(rb[k].sample.id_initiator, st) - b.devicePosition(rb[k].sample.id_responder, st)).norm() +
             bias.gamma_m;
    };
    EXPECT_NEAR(rb[k].sample.range_m, at(rb[k].sample.t.sec() - 0.05), 1e-9);
    moved = std::max(moved, std::abs(rb[k].sample.range_m - at(rb[k].sample.t.sec())));
  }
  EXPECT_GT(moved, 0.01) << "the vehicle moves: 50 ms change some distances by centimetres";
  ASSERT_FALSE(rc.empty());
  EXPECT_GE(rc.front().sample.t.us, 0);
  EXPECT_LT(rc.size(), ra.size());  // slots in the first 0.05 s would be stamped before 0
}
