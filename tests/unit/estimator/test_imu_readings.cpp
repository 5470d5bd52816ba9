/// The readings a propagation step holds (imu_readings.h): exact on linear signals, held where
/// extrapolation is not allowed, dead reckoning of a simulated walk cut by range updates, and the
/// estimator node's heading on the walk where the held readings showed (seed-6 run153).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "estimator/core/so3.h"
#include "estimator/imu/imu_propagator.h"
#include "estimator/imu/imu_readings.h"
#include "estimator/node/estimator_node.h"
#include "sim/imu_simulator.h"
#include "sim/scenario_simulator.h"
#include "sim/trajectory_factory.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {
ImuSample sample(double t_s, double acc, double gyro) {
  ImuSample s;
  s.t = Timestamp::fromSec(t_s);
  s.acc_m_s2 = Eigen::Vector3d(acc, -2.0 * acc, 0.5 * acc);
  s.gyro_rad_s = Eigen::Vector3d(gyro, 0.0, -gyro);
  return s;
}
Timestamp at(double t_s) { return Timestamp::fromSec(t_s); }
}  // namespace

TEST(ImuReadings, InterpolatedToTheMiddleOfTheStep) {
  // u(t) = 1 + 2 t: the middle of [0.012, 0.015] is 0.0135.
  const ImuReading u = readingBetween(sample(0.010, 1.02, 0.5), sample(0.015, 1.03, 1.0), at(0.012), at(0.015));
  EXPECT_NEAR(u.acc_m_s2.x(), 1.027, 1e-12);
  EXPECT_NEAR(u.acc_m_s2.y(), -2.054, 1e-12);
  EXPECT_NEAR(u.gyro_rad_s.x(), 0.5 + 0.5 * 0.7, 1e-12);
  // Two samples at one time: the newer one.
  EXPECT_EQ(readingBetween(sample(0.010, 1.0, 0.0), sample(0.010, 3.0, 0.0), at(0.010), at(0.010)).acc_m_s2.x(), 3.0);
}

TEST(ImuReadings, ExtrapolatedPastTheLastSampleWithinOnePeriod) {
  // u(t) = 1 + 2 t sampled at 0.010 and 0.015; the step [0.015, 0.018] has its middle at 0.0165.
  const ImuSample prev = sample(0.010, 1.02, 0.5), last = sample(0.015, 1.03, 1.0);
  const ImuReading u = readingPast(last, prev, at(0.015), at(0.018), 0.1);
  EXPECT_NEAR(u.acc_m_s2.x(), 1.033, 1e-12);
  EXPECT_NEAR(u.acc_m_s2.z(), 0.5 * 1.033, 1e-12);
  EXPECT_NEAR(u.gyro_rad_s.x(), 1.0 + 0.5 * 0.3, 1e-12);
  // w = 0.3: (1.3² + 0.3² − 1) of one sample's variance over 3 ms of a 5 ms period.
  EXPECT_NEAR(u.extra_noise_scale, 0.78 * 0.6, 1e-12);
  // The rest of that step, after an update at 0.018: middle 0.019.
  EXPECT_NEAR(readingPast(last, prev, at(0.018), at(0.020), 0.1).acc_m_s2.x(), 1.038, 1e-12);
}

TEST(ImuReadings, FollowsTheSlopeOnlyWhileTheNextSampleIsDue) {
  // u(t) = 1 + 200 t sampled at 0.010 and 0.015 (period 5 ms); the next sample is late.
  const ImuSample prev = sample(0.010, 3.0, 0.5), last = sample(0.015, 4.0, 1.0);
  // [0.015, 0.0201] (jitter): the end is taken at 0.020, so the middle at 0.0175.
  EXPECT_NEAR(readingPast(last, prev, at(0.015), at(0.0201), 0.1).acc_m_s2.x(), 4.5, 1e-12);
  // [0.019, 0.0248], within two periods (one sample dropped): the ends taken at most at 0.020,
  // the middle at 0.0195.
  EXPECT_NEAR(readingPast(last, prev, at(0.019), at(0.0248), 0.1).acc_m_s2.x(), 4.9, 1e-12);
  // [0.021, 0.030], beyond two periods: samples missing, possibly an IMU gap; held.
  EXPECT_EQ(readingPast(last, prev, at(0.021), at(0.030), 0.1).acc_m_s2.x(), 4.0);
  EXPECT_EQ(readingPast(last, prev, at(0.021), at(0.030), 0.1).extra_noise_scale, 0.0);
}

TEST(ImuReadings, HeldWhereExtrapolationIsNotAllowed) {
  const ImuSample prev = sample(0.010, 1.0, 0.5), last = sample(0.015, 2.0, 1.0);
  // No earlier sample (the first after an initialization).
  EXPECT_EQ(readingPast(last, std::nullopt, at(0.015), at(0.018), 0.1).acc_m_s2.x(), 2.0);
  // The last two samples further apart than the limit (dropped samples between them).
  EXPECT_EQ(readingPast(last, prev, at(0.015), at(0.018), 0.004).acc_m_s2.x(), 2.0);
  // Extrapolation switched off (imu.extrapolate_max_period_s: 0).
  EXPECT_EQ(readingPast(last, prev, at(0.015), at(0.018), 0.0).acc_m_s2.x(), 2.0);
  // A step starting before the last sample is not a step past it.
  EXPECT_EQ(readingPast(last, prev, at(0.014), at(0.016), 0.1).acc_m_s2.x(), 2.0);
  // Held and interpolated readings carry a sample's own noise, which the process noise budgets.
  EXPECT_EQ(readingPast(last, std::nullopt, at(0.015), at(0.018), 0.1).extra_noise_scale, 0.0);
  EXPECT_EQ(readingBetween(prev, last, at(0.012), at(0.015)).extra_noise_scale, 0.0);
}

namespace {
/// A trajectory of the simulator's kind `kind` in a hall of `hall_m` [m].
std::unique_ptr<sim::Trajectory> trajectoryOf(sim::TrajectoryKind kind, uint64_t seed, double duration_s,
                                              const Eigen::Vector3d& hall_m) {
  sim::SimulationOptions o;
  o.trajectory_kind = kind;
  o.seed = seed;
  o.duration_s = duration_s;
  o.hall_size_m = hall_m;
  return sim::makeTrajectory(o);
}

/// Largest position [m] and attitude [deg] errors of noise-free dead reckoning from the truth over
/// 5 s windows of a simulated walk at 200 Hz, each IMU step cut where a range of the meshed TDMA
/// schedule (a slot every 10 ms, `phase_s` after a sample) comes before the next sample.
std::pair<double, double> walkDeadReckoning(bool extrapolate, double phase_s) {
  const auto walk = trajectoryOf(sim::TrajectoryKind::Walk, 3, 60.0, Eigen::Vector3d(11.5, 10.4, 6.8));
  sim::ImuNoiseOptions noise = sim::ImuNoiseOptions::noiseless();
  noise.rate_hz = 200.0;
  sim::ImuSimulator simulator(noise, 1);
  const std::vector<ImuSample> imu = simulator.simulate(*walk, walk->duration());
  const ImuPropagator prop(9.81, ImuNoiseOptions{});
  double worst_p = 0.0, worst_deg = 0.0;
  for (size_t k0 = 1; k0 + 1000 < imu.size(); k0 += 1000) {
    const sim::TrajectoryState start = walk->evaluate(imu[k0].t.sec());
    ImuState x;
    x.p_IinG = start.p_IinG;
    x.v_IinG = start.v_IinG;
    x.q_ItoG = start.q_ItoG;
    for (size_t k = k0; k < k0 + 1000; ++k) {
      Timestamp t0 = imu[k].t;
      const Timestamp range_t = Timestamp::fromSec(phase_s + 0.01 * std::ceil((imu[k].t.sec() - phase_s) / 0.01));
      if (range_t > imu[k].t && range_t < imu[k + 1].t) {
        const double max_period_s = ImuNoiseOptions{}.extrapolate_max_period_s;
        const ImuReading u = extrapolate ? readingPast(imu[k], imu[k - 1], t0, range_t, max_period_s)
                                         : ImuReading{imu[k].acc_m_s2, imu[k].gyro_rad_s};
        prop.propagate(x, u.acc_m_s2, u.gyro_rad_s, (range_t - t0).sec(), nullptr, nullptr);
        t0 = range_t;
      }
      const ImuReading u = readingBetween(imu[k], imu[k + 1], t0, imu[k + 1].t);
      prop.propagate(x, u.acc_m_s2, u.gyro_rad_s, (imu[k + 1].t - t0).sec(), nullptr, nullptr);
    }
    const sim::TrajectoryState end = walk->evaluate(imu[k0 + 1000].t.sec());
    worst_p = std::max(worst_p, (x.p_IinG - end.p_IinG).norm());
    worst_deg = std::max(worst_deg, end.q_ItoG.angularDistance(x.q_ItoG) * 180.0 / M_PI);
  }
  return {worst_p, worst_deg};
}
}  // namespace

TEST(ImuReadings, AWalkCutByRangeUpdatesDeadReckonsToAMillimetre) {
  // The simulator draws the TDMA phase per sequence; 4.8 ms is about the worst (the cut part is
  // nearly the whole step).
  for (double phase_s : {0.001, 0.0025, 0.0048}) {
    const auto [p_m, deg] = walkDeadReckoning(true, phase_s);
    std::printf("walk, ranges %.1f ms after a sample, worst 5 s window: extrapolated %.4f m %.4f deg\n",
                1e3 * phase_s, p_m, deg);
    EXPECT_LT(p_m, 0.003) << phase_s;
    EXPECT_LT(deg, 0.003) << phase_s;
  }
  // The latest reading held instead: centimetres, several times a tactical IMU's noise over 5 s.
  const auto [held_p_m, held_deg] = walkDeadReckoning(false, 0.0048);
  std::printf("walk, ranges 4.8 ms after a sample, worst 5 s window: held %.4f m %.4f deg\n", held_p_m, held_deg);
  EXPECT_GT(held_p_m, 0.02);
  EXPECT_GT(held_deg, 0.02);
}

namespace {
/// How a propagation step cut by a measurement at `range_t` (between samples k and k+1) is split.
enum class CutReadings { kUncut, kExtrapolated, kInterpolated };

/// Attitude [deg] and position [m] differences after 60 s between noise-free dead reckoning of a
/// figure-eight flight (the widened sweep's run001: tactical IMU whose only error is the rotors'
/// vibration) with every other IMU step cut by a range 2.4 ms after its sample, and the same
/// integration uncut.
std::pair<double, double> vibratingFlightCutDrift(CutReadings mode) {
  const auto flight = trajectoryOf(sim::TrajectoryKind::Figure8, 763775, 61.0, Eigen::Vector3d(9.0, 8.7, 6.3));
  sim::ImuNoiseOptions noise = sim::ImuNoiseOptions::noiseless();
  const sim::ImuNoiseOptions vibrating;  // the default rotor vibration
  noise.vibration_acc_m_s2 = vibrating.vibration_acc_m_s2;
  noise.vibration_gyro_rad_s = vibrating.vibration_gyro_rad_s;
  sim::ImuSimulator simulator(noise, 1);
  const std::vector<ImuSample> imu = simulator.simulate(*flight, 60.0);
  const ImuPropagator prop(9.81, ImuNoiseOptions{});
  const double max_period_s = ImuNoiseOptions{}.extrapolate_max_period_s;
  auto integrate = [&](CutReadings how) {
    ImuState x;
    const sim::TrajectoryState start = flight->evaluate(imu[1].t.sec());
    x.p_IinG = start.p_IinG;
    x.v_IinG = start.v_IinG;
    x.q_ItoG = start.q_ItoG;
    for (size_t k = 1; k + 1 < imu.size(); ++k) {
      Timestamp t0 = imu[k].t;
      const Timestamp range_t = imu[k].t + Duration::fromSec(0.0024);
      if (how != CutReadings::kUncut && k % 2 == 0) {
        const ImuReading u = how == CutReadings::kExtrapolated
                                 ? readingPast(imu[k], imu[k - 1], t0, range_t, max_period_s)
                                 : readingBetween(imu[k], imu[k + 1], t0, range_t);
        prop.propagate(x, u.acc_m_s2, u.gyro_rad_s, (range_t - t0).sec(), nullptr, nullptr);
        t0 = range_t;
      }
      const ImuReading u = readingBetween(imu[k], imu[k + 1], t0, imu[k + 1].t);
      prop.propagate(x, u.acc_m_s2, u.gyro_rad_s, (imu[k + 1].t - t0).sec(), nullptr, nullptr);
    }
    return x;
  };
  const ImuState uncut = integrate(CutReadings::kUncut);
  const ImuState cut = mode == CutReadings::kUncut ? uncut : integrate(mode);
  return {uncut.q_ItoG.angularDistance(cut.q_ItoG) * 180.0 / M_PI, (uncut.p_IinG - cut.p_IinG).norm()};
}
}  // namespace

TEST(ImuReadings, ARotorsVibrationIsNotRectifiedWhenACutStepIsInterpolatedBetweenItsSamples) {
  // Extrapolating the cut part integrates −(Δt/8)(u_{k+1} − 2u_k + u_{k−1}) more than the uncut
  // step; at a fixed phase, cut every other step, the vibration's aliased tones are rectified
  // into a steady velocity error. Interpolating between the step's two
  // samples (the node holds the measurement until the second has come) integrates the samples'
  // linear interpolant exactly, as the uncut step does.
  const auto [extrapolated_deg, extrapolated_m] = vibratingFlightCutDrift(CutReadings::kExtrapolated);
  const auto [interpolated_deg, interpolated_m] = vibratingFlightCutDrift(CutReadings::kInterpolated);
  std::printf("vibrating figure-eight, 60 s, every other step cut: extrapolated %.4f deg %.4f m, interpolated %.6f deg %.6f m\n",
              extrapolated_deg, extrapolated_m, interpolated_deg, interpolated_m);
  // Measured: extrapolated 0.29 m, interpolated 0.01 m (the attitude's integration splits a step
  // in two, which is not exactly the uncut step's rotation); attitudes 0.0008° and 0.0001°.
  EXPECT_LT(interpolated_deg, 1e-3);
  EXPECT_LT(interpolated_m, 0.03);
  EXPECT_GT(extrapolated_m, 10.0 * interpolated_m);
}

namespace {
/// Orientation ANEES of the estimator node over seed-6 run153 of the robustness sweep without its
/// outliers (a 90 s walk, three anchors on one wall, three tags, tactical IMU, σ_d 0.199 m), at
/// the ground-truth samples that coincide with a pose output, from 10 s on.
double walkOrientationAnees(double extrapolate_max_period_s, bool hold_for_next_sample) {
  sim::SimulationOptions o;
  o.seed = 234995;
  o.trajectory_kind = sim::TrajectoryKind::Walk;
  o.hall_size_m = Eigen::Vector3d(11.5, 10.4, 6.8);
  o.anchor_layout = sim::AnchorLayoutKind::OneWall;
  o.n_tags = 3;
  o.n_known_anchors = 3;
  o.n_unknown_anchors = 2;  // in the TDMA schedule; their ranges are not used
  o.uwb.sigma_range_m = 0.199;
  o.uwb.outlier_fraction = 0.0;
  o.uwb.drop_fraction = 0.038;
  o.imu = sim::ImuNoiseOptions::forGrade("tactical");
  o.duration_s = 90.0;
  const Dataset ds = sim::ScenarioSimulator(o).run().dataset;
  std::vector<PoseEstimate> poses;
  EstimatorSinks sinks;
  sinks.pose = [&](const PoseEstimate& e) { poses.push_back(e); };
  EstimatorOptions opt;
  opt.imu.extrapolate_max_period_s = extrapolate_max_period_s;
  opt.imu.hold_for_next_sample = hold_for_next_sample;
  EstimatorNode node(opt, ds.setup, sinks);
  for (const auto& in : mergeInTimeOrder(ds)) node.onInput(in);
  EXPECT_TRUE(node.initialized());
  double sum = 0.0;
  int n = 0;
  size_t j = 0;
  for (const PoseEstimate& e : poses) {
    while (j < ds.ground_truth.size() && ds.ground_truth[j].t < e.t) ++j;
    if (j == ds.ground_truth.size()) break;
    if (ds.ground_truth[j].t != e.t || e.t.sec() < 10.0) continue;
    const Eigen::Vector3d dtheta = so3::logMap(Eigen::Matrix3d(e.q_ItoG.toRotationMatrix().transpose() *
                                                              ds.ground_truth[j].q_ItoG.toRotationMatrix()));
    sum += dtheta.dot(e.cov_theta_rad2.ldlt().solve(dtheta));
    ++n;
  }
  EXPECT_GT(n, 1000);
  return n > 0 ? sum / n : 1e300;
}
}  // namespace

TEST(ImuReadings, TheEstimatorsHeadingOnATacticalWalkIsConsistent) {
  const double anees = walkOrientationAnees(ImuNoiseOptions{}.extrapolate_max_period_s, true);
  const double anees_extrapolated = walkOrientationAnees(ImuNoiseOptions{}.extrapolate_max_period_s, false);
  const double anees_held = walkOrientationAnees(0.0, false);
  std::printf("run153 without outliers, orientation ANEES from 10 s: %.1f interpolated (held for the next sample), "
              "%.1f extrapolated, %.1f held\n", anees, anees_extrapolated, anees_held);
  // χ²(3) has mean 3; the held readings made the heading ten times overconfident.
  EXPECT_LT(anees, 6.0);
  EXPECT_LT(anees_extrapolated, 6.0);
  EXPECT_GT(anees_held, 15.0);
}
