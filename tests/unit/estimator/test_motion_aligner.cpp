/// In-motion alignment (MotionAligner) on the simulated paper flight: exact with noise-free data,
/// consistent with noise, refused while landed (yaw unobservable) and without enough anchors.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <random>

#include "estimator/core/so3.h"
#include "estimator/init/motion_aligner.h"
#include "sim/imu_simulator.h"
#include "sim/paper_scenario.h"
#include "sim/spiral_trajectory.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

/// The paper's flight with eight turns instead of three and a fixed heading: centripetal
/// accelerations of ~0.5 m/s² that turn in the body frame make yaw observable within a window.
/// (On the paper's slow spiral, or with a heading that follows the turn, a constant body-frame
/// acceleration is indistinguishable from an accelerometer bias and the aligner refuses.)
sim::TrajectoryOptions fastSpiral() {
  sim::TrajectoryOptions o = sim::TrajectoryOptions::randomized(1);
  o.turns = 8.0;
  o.yaw_follow = 0.0;
  return o;
}

struct Flight {
  sim::SpiralTrajectory trajectory{fastSpiral()};
  sim::PaperScenario scenario = sim::PaperScenario::paper();
  std::vector<ImuSample> imu;
  Flight(double acc_noise, double gyro_noise) {
    sim::ImuNoiseOptions o;
    o.acc_noise_density = acc_noise;
    o.gyro_noise_density = gyro_noise;
    o.acc_bias_rw = o.gyro_bias_rw = 0.0;
    o.acc_bias_initial_sigma = o.gyro_bias_initial_sigma = 0.0;
    o.vibration_acc_m_s2 = o.vibration_gyro_rad_s = 0.0;  // white noise only: the aligner's own model
    imu = sim::ImuSimulator(o, 3).simulate(trajectory, trajectory.duration());
  }
};

/// Feeds [t0, t1] of the flight: IMU and ranges from tag 100 (only) to `anchors` every 25 ms.
/// `R_GtoG2` re-expresses the anchors (only) in another frame G2: the ranges stay those of G.
void feed(MotionAligner& a, const Flight& f, double t0, double t1, const std::vector<SensorId>& anchors,
          double sigma_m, std::mt19937_64* rng, const Eigen::Matrix3d& R_GtoG2 = Eigen::Matrix3d::Identity()) {
  std::normal_distribution<double> n01(0.0, 1.0);
  for (const ImuSample& s : f.imu)
    if (s.t.sec() >= t0 && s.t.sec() <= t1) a.addImu(s);
  int k = 0;
  for (double t = t0 + 0.0123; t < t1; t += 0.025, ++k) {
    const sim::TrajectoryState st = f.trajectory.evaluate(t);
    const SensorId anchor = anchors[k % anchors.size()];
    AlignRange r;
    r.t = Timestamp::fromSec(t);
    r.tag = 100;
    r.anchor = anchor;
    r.p_AinG = f.scenario.anchors_p_AinG.at(anchor);
    r.d_m = (r.p_AinG - st.p_IinG - st.R_ItoG * f.scenario.tags_p_TinI.at(100)).norm() + (rng ? sigma_m * n01(*rng) : 0.0);
    r.p_AinG = R_GtoG2 * r.p_AinG;
    r.sigma_m = sigma_m;
    a.addRange(r);
  }
}

double yawError(const ImuState& x, const sim::TrajectoryState& st) {
  const Eigen::Matrix3d R = x.q_ItoG.toRotationMatrix();
  return std::remainder(std::atan2(R(1, 0), R(0, 0)) - std::atan2(st.R_ItoG(1, 0), st.R_ItoG(0, 0)), 2 * M_PI);
}

}  // namespace

TEST(MotionAligner, NoiseFreeFlightGivesTheExactPose) {
  const Flight f(0.0, 0.0);
  MotionAligner a(MotionAlignerOptions{}, {{100, sim::PaperScenario::paper().tags_p_TinI.at(100)}});
  feed(a, f, 40.0, 46.0, {101, 102, 103, 104}, 0.05, nullptr);
  const auto res = a.solve(Eigen::Vector3d::Zero());
  ASSERT_TRUE(res) << a.reason();
  const sim::TrajectoryState st = f.trajectory.evaluate(res->t.sec());
  EXPECT_LT((res->imu.p_IinG - st.p_IinG).norm(), 2e-3);
  EXPECT_LT((res->imu.v_IinG - st.v_IinG).norm(), 2e-3);
  EXPECT_LT(Eigen::AngleAxisd(res->imu.q_ItoG.toRotationMatrix().transpose() * st.R_ItoG).angle(), 1e-3);
  EXPECT_LT(res->imu.bias_acc_m_s2.norm(), 1e-2);
  EXPECT_LT(res->rms_m, 1e-3);
}

TEST(MotionAligner, NoisyWindowsAreConsistent) {
  const Flight f(2e-3, 2e-4);
  std::mt19937_64 rng(5);
  int n = 0;
  double nees_sum = 0.0;
  for (double t0 = 20.0; t0 < 110.0; t0 += 6.0) {
    MotionAligner a(MotionAlignerOptions{}, {{100, sim::PaperScenario::paper().tags_p_TinI.at(100)}});
    feed(a, f, t0, t0 + 6.0, {101, 102, 103, 104}, 0.1, &rng);
    const auto res = a.solve(Eigen::Vector3d::Zero());
    if (!res) continue;  // a window without enough horizontal acceleration is refused, not wrong
    const sim::TrajectoryState st = f.trajectory.evaluate(res->t.sec());
    Eigen::Matrix<double, 9, 1> e;
    e << res->imu.p_IinG - st.p_IinG, res->imu.v_IinG - st.v_IinG,
        so3::logMap(res->imu.q_ItoG.conjugate() * st.q_ItoG);
    nees_sum += e.dot(res->cov.topLeftCorner<9, 9>().ldlt().solve(e));
    EXPECT_LT(std::abs(yawError(res->imu, st)), 3.0 * res->sigma_yaw_deg * M_PI / 180.0 + 0.02) << "t0 " << t0;
    ++n;
  }
  ASSERT_GE(n, 10);
  // Honest covariance: mean NEES (9 dof) well inside a generous consistency band.
  EXPECT_LT(nees_sum / n, 2.0 * 9.0);
  EXPECT_GT(nees_sum / n, 0.1 * 9.0);
}

TEST(MotionAligner, RefusesWhileLandedWithOneTag) {
  const Flight f(2e-3, 2e-4);
  MotionAligner a(MotionAlignerOptions{}, {{100, sim::PaperScenario::paper().tags_p_TinI.at(100)}});
  std::mt19937_64 rng(1);
  feed(a, f, 0.0, 4.5, {101, 102, 103, 104}, 0.1, &rng);  // on the pad: yaw cannot be seen
  EXPECT_FALSE(a.solve(Eigen::Vector3d::Zero()));
  // Either reason says the same: headings far apart fit alike (ambiguous) or σ_yaw is too large.
  EXPECT_TRUE(a.reason().find("not determined") != std::string::npos ||
              a.reason().find("ambiguous") != std::string::npos)
      << a.reason();
}

TEST(MotionAligner, AHeadingPriorFixesTheHeadingTheRangesLeaveOpen) {
  // On the pad one tag's ranges fix position and tilt, never the heading: refused without a prior.
  // A lost filter's heading (the gyro kept it through a range outage) decides among the rivals and
  // is combined with the fit: the pose is taken, its heading within the prior's σ of the truth, the
  // position the ranges' own.
  const Flight f(2e-3, 2e-4);
  const sim::TrajectoryState st = f.trajectory.evaluate(4.5);
  const double yaw_true = std::atan2(st.R_ItoG(1, 0), st.R_ItoG(0, 0));
  for (const double offset_deg : {0.0, 4.0}) {
    MotionAligner a(MotionAlignerOptions{}, {{100, sim::PaperScenario::paper().tags_p_TinI.at(100)}});
    std::mt19937_64 rng(1);
    feed(a, f, 0.0, 4.5, {101, 102, 103, 104}, 0.1, &rng);
    ASSERT_FALSE(a.solve(Eigen::Vector3d::Zero()));
    const double sigma_rad = 3.0 * M_PI / 180.0;
    const auto r = a.solve(Eigen::Vector3d::Zero(),
                           MotionAligner::HeadingPrior{yaw_true + offset_deg * M_PI / 180.0, sigma_rad * sigma_rad});
    ASSERT_TRUE(r) << a.reason();
    const sim::TrajectoryState s_end = f.trajectory.evaluate(r->t.sec());
    EXPECT_LT(std::abs(yawError(r->imu, s_end)) * 180.0 / M_PI, offset_deg + 3.0 * r->sigma_yaw_deg) << offset_deg;
    EXPECT_LE(r->sigma_yaw_deg, 3.0 + 1e-9);  // the prior's σ, or less where the data add to it
    EXPECT_LT((r->imu.p_IinG - s_end.p_IinG).norm(), 0.3);
  }
}

TEST(MotionAligner, AHeadingPriorTheFitContradictsIsNotTaken) {
  // In flight one tag's 6 s window fixes the heading on its own (σ_ψ about 19°): a lost filter's
  // heading 120° off (σ 3°, r²/s about 38) is its own error. The fit is taken as without a prior
  // (same pose, same heading) and the rejection is counted; a prior that agrees is fused and
  // narrows the heading.
  const Flight f(2e-3, 2e-4);
  auto solveWith = [&](const std::optional<MotionAligner::HeadingPrior>& prior, int* rejections) {
    MotionAligner a(MotionAlignerOptions{}, {{100, sim::PaperScenario::paper().tags_p_TinI.at(100)}});
    std::mt19937_64 rng(7);
    feed(a, f, 40.0, 46.0, {101, 102, 103, 104}, 0.1, &rng);
    auto r = a.solve(Eigen::Vector3d::Zero(), prior);
    *rejections = a.headingPriorRejections();
    return r;
  };
  int rejections = 0;
  const auto free = solveWith(std::nullopt, &rejections);
  ASSERT_TRUE(free);
  const double yaw = so3::yawOf(free->imu.q_ItoG), var = std::pow(3.0 * M_PI / 180.0, 2);
  const auto wrong = solveWith(MotionAligner::HeadingPrior{yaw + 120.0 * M_PI / 180.0, var}, &rejections);
  ASSERT_TRUE(wrong);
  EXPECT_EQ(rejections, 1);
  EXPECT_EQ(wrong->imu.q_ItoG.coeffs(), free->imu.q_ItoG.coeffs());
  EXPECT_EQ(wrong->imu.p_IinG, free->imu.p_IinG);
  const auto agreeing = solveWith(MotionAligner::HeadingPrior{yaw, var}, &rejections);
  ASSERT_TRUE(agreeing);
  EXPECT_EQ(rejections, 0);
  EXPECT_LT(agreeing->sigma_yaw_deg, free->sigma_yaw_deg);
  EXPECT_NEAR(so3::yawOf(agreeing->imu.q_ItoG), yaw, 1e-9);
}

TEST(MotionAligner, RefusesWithTwoAnchorsOrAShortWindow) {
  const Flight f(0.0, 0.0);
  MotionAligner a(MotionAlignerOptions{}, {{100, sim::PaperScenario::paper().tags_p_TinI.at(100)}});
  feed(a, f, 40.0, 41.0, {101, 102, 103, 104}, 0.05, nullptr);
  EXPECT_FALSE(a.solve(Eigen::Vector3d::Zero()));
  EXPECT_NE(a.reason().find("s of IMU data"), std::string::npos) << a.reason();
  a.clear();
  feed(a, f, 40.0, 46.0, {101, 102}, 0.05, nullptr);
  EXPECT_FALSE(a.solve(Eigen::Vector3d::Zero()));
  EXPECT_NE(a.reason().find("known anchors"), std::string::npos) << a.reason();
}

TEST(MotionAligner, PaperSpiralWithOneTagIsHonest) {
  // The paper's slow spiral, one tag, a consumer-like IMU with biases: yaw is weakly observable,
  // so windows are refused or accepted with a σ_yaw that covers the error.
  Flight f(2e-3, 2e-4);
  f.trajectory = sim::SpiralTrajectory(sim::TrajectoryOptions::randomized(1));
  f.imu = sim::ImuSimulator(sim::ImuNoiseOptions{}, 3).simulate(f.trajectory, f.trajectory.duration());
  std::mt19937_64 rng(5);
  int accepted = 0;
  for (double t1 = 13.0; t1 < 60.0; t1 += 2.0) {
    MotionAligner a(MotionAlignerOptions{}, {{100, sim::PaperScenario::paper().tags_p_TinI.at(100)}});
    feed(a, f, t1 - 12.0, t1, {101, 102, 103, 104}, 0.1, &rng);
    const auto res = a.solve(Eigen::Vector3d::Zero());
    if (!res) continue;
    ++accepted;
    const sim::TrajectoryState st = f.trajectory.evaluate(res->t.sec());
    EXPECT_LT(std::abs(yawError(res->imu, st)) * 180.0 / M_PI, 3.0 * res->sigma_yaw_deg) << t1;
    EXPECT_LT((res->imu.p_IinG - st.p_IinG).norm(), 3.0 * std::sqrt(3.0) * res->sigma_p_m) << t1;
    EXPECT_LE(res->sigma_yaw_deg, MotionAlignerOptions{}.max_sigma_yaw_deg);
  }
  EXPECT_GE(accepted, 15);
}

namespace {

/// Downward rangefinder at p_IH reading the beam length to the floor z = 0 plus `bias`, at 5 Hz.
void feedHeights(MotionAligner& a, const Flight& f, double t0, double t1, const Eigen::Vector3d& p_IH, double bias) {
  for (double t = t0 + 0.0071; t < t1; t += 0.2) {
    const sim::TrajectoryState st = f.trajectory.evaluate(t);
    const double s_z = (st.p_IinG + st.R_ItoG * p_IH).z();
    a.addHeight({Timestamp::fromSec(t), s_z / st.R_ItoG(2, 2) + bias, 0.05});
  }
}

/// Sparse ranging as on MILUV: one range every `period_s`, cycling through `anchors`.
void feedSparse(MotionAligner& a, const Flight& f, double t0, double t1, const std::vector<SensorId>& anchors,
                double period_s) {
  for (const ImuSample& s : f.imu)
    if (s.t.sec() >= t0 && s.t.sec() <= t1) a.addImu(s);
  int k = 0;
  for (double t = t0 + 0.0123; t < t1; t += period_s, ++k) {
    const sim::TrajectoryState st = f.trajectory.evaluate(t);
    AlignRange r;
    r.t = Timestamp::fromSec(t);
    r.tag = 100;
    r.anchor = anchors[k % anchors.size()];
    r.p_AinG = f.scenario.anchors_p_AinG.at(r.anchor);
    r.d_m = (r.p_AinG - st.p_IinG - st.R_ItoG * f.scenario.tags_p_TinI.at(100)).norm();
    r.sigma_m = 0.05;
    a.addRange(r);
  }
}

}  // namespace

TEST(MotionAligner, NoiseFreeHeightsGiveTheExactPoseAndTheRangefinderBias) {
  const Flight f(0.0, 0.0);
  MotionAlignerOptions o;
  o.p_IH = Eigen::Vector3d(0.05, 0.02, -0.1);
  MotionAligner a(o, {{100, sim::PaperScenario::paper().tags_p_TinI.at(100)}});
  feed(a, f, 40.0, 46.0, {101, 102, 103, 104}, 0.05, nullptr);
  feedHeights(a, f, 40.0, 46.0, o.p_IH, 0.12);
  const auto res = a.solve(Eigen::Vector3d::Zero());
  ASSERT_TRUE(res) << a.reason();
  const sim::TrajectoryState st = f.trajectory.evaluate(res->t.sec());
  EXPECT_LT((res->imu.p_IinG - st.p_IinG).norm(), 2e-3);
  EXPECT_LT(Eigen::AngleAxisd(res->imu.q_ItoG.toRotationMatrix().transpose() * st.R_ItoG).angle(), 1e-3);
  EXPECT_EQ(res->n_heights, 30);
  EXPECT_NEAR(res->height_bias_m, 0.12, 2e-3);
  EXPECT_LT(res->height_bias_var_m2, 0.05 * 0.05);
}

TEST(MotionAligner, SparseRangesMakeTheWindowReachBackByCount) {
  const Flight f(0.0, 0.0);
  MotionAlignerOptions o;  // 12 s window, 20 ranges needed, at most 40 s back
  MotionAligner a(o, {{100, sim::PaperScenario::paper().tags_p_TinI.at(100)}});
  feedSparse(a, f, 20.0, 50.0, {101, 102, 103, 104}, 0.8);  // 15 ranges per 12 s
  feedHeights(a, f, 20.0, 50.0, o.p_IH, 0.0);
  const auto res = a.solve(Eigen::Vector3d::Zero());
  ASSERT_TRUE(res) << a.reason();
  EXPECT_EQ(res->n_ranges, 20);
  EXPECT_GT(res->window_s, 15.0);  // back to the 20th newest range (34.81 s), not 12 s
  EXPECT_LT(res->window_s, 16.5);
  const sim::TrajectoryState st = f.trajectory.evaluate(res->t.sec());
  EXPECT_LT((res->imu.p_IinG - st.p_IinG).norm(), 1e-2);
  // Never further back than max_window_s: with 40 s of ranges every 3 s the fit holds 13 and refuses.
  MotionAligner b(o, {{100, sim::PaperScenario::paper().tags_p_TinI.at(100)}});
  feedSparse(b, f, 10.0, 60.0, {101, 102, 103, 104}, 3.0);
  EXPECT_FALSE(b.solve(Eigen::Vector3d::Zero()));
  EXPECT_NE(b.reason().find("need 20"), std::string::npos) << b.reason();
  EXPECT_NEAR(b.spanSeconds(), 40.0, 0.01);
}

TEST(MotionAligner, HeightsRemoveTheMirrorImageAcrossCoplanarAnchors) {
  // Anchors all 9 m up (one plane above the flight): the trajectory mirrored across that plane
  // fits the ranges alike. The rangefinder (floor at z = 0) tells the two apart.
  Flight f(0.0, 0.0);
  for (SensorId id : {101, 102, 103, 104}) f.scenario.anchors_p_AinG.at(id).z() = 9.0;
  // 6 s windows (in longer ones the accelerometer alone tells the two apart); yaw is weak under
  // one plane of anchors, so its limit is raised: this test is about the position.
  MotionAlignerOptions o;
  o.max_sigma_yaw_deg = 40.0;
  MotionAligner without(o, {{100, sim::PaperScenario::paper().tags_p_TinI.at(100)}});
  std::mt19937_64 rng(3);
  feed(without, f, 40.0, 46.0, {101, 102, 103, 104}, 0.1, &rng);
  const auto r0 = without.solve(Eigen::Vector3d::Zero());
  EXPECT_FALSE(r0) << "z " << r0->imu.p_IinG.z();
  EXPECT_NE(without.reason().find("ambiguous"), std::string::npos) << without.reason();
  MotionAligner with(o, {{100, sim::PaperScenario::paper().tags_p_TinI.at(100)}});
  rng.seed(3);
  feed(with, f, 40.0, 46.0, {101, 102, 103, 104}, 0.1, &rng);
  feedHeights(with, f, 40.0, 46.0, o.p_IH, 0.0);
  const auto r1 = with.solve(Eigen::Vector3d::Zero());
  ASSERT_TRUE(r1) << with.reason();
  const sim::TrajectoryState st = f.trajectory.evaluate(r1->t.sec());
  // The mirror image is ~10 m away; the fit is within its own σ of the truth.
  EXPECT_LT((r1->imu.p_IinG - st.p_IinG).norm(), 3.0 * std::sqrt(3.0) * r1->sigma_p_m);
  EXPECT_LT((r1->imu.p_IinG - st.p_IinG).norm(), 0.5);
  EXPECT_GT(r1->n_heights, 25);
}

// The anchors' frame upside down (half a turn about x: z points down, as ISAS-Walk1's RTLS frame):
// the same ranges and IMU fit decisively better with gravity along +z of that frame, and the
// check says so; in the true frame it says the opposite. Heights (floor below, along −z) are not
// checked.
TEST(MotionAligner, GravityCheckFindsAnUpsideDownAnchorFrame) {
  const Flight f(0.02, 0.002);
  const std::map<SensorId, Eigen::Vector3d> tags{{100, sim::PaperScenario::paper().tags_p_TinI.at(100)}};
  const Eigen::Matrix3d R_flip = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  for (const bool upside_down : {false, true}) {
    std::mt19937_64 rng(5);
    MotionAligner a(MotionAlignerOptions{}, tags);
    feed(a, f, 40.0, 52.0, {101, 102, 103, 104}, 0.1, &rng,
         upside_down ? R_flip : Eigen::Matrix3d::Identity());
    const auto c = a.checkGravityDirection(Eigen::Vector3d::Zero());
    ASSERT_TRUE(c) << a.reason();
    EXPECT_EQ(c->zDown(), upside_down) << c->cost_z_up << " vs " << c->cost_z_down << ", margin " << c->margin;
    EXPECT_EQ(c->zUp(), !upside_down) << c->cost_z_up << " vs " << c->cost_z_down << ", margin " << c->margin;
    EXPECT_EQ(c->n_ranges, 400);  // about 480 ranges in the window, thinned evenly to the fit's bound
    // The check leaves the aligner's convention alone: a solve afterwards is the one without it.
    if (!upside_down) {
      std::mt19937_64 rng2(5);
      MotionAligner fresh(MotionAlignerOptions{}, tags);
      feed(fresh, f, 40.0, 52.0, {101, 102, 103, 104}, 0.1, &rng2);
      const auto res = a.solve(Eigen::Vector3d::Zero());
      const auto ref = fresh.solve(Eigen::Vector3d::Zero());
      ASSERT_TRUE(res && ref) << a.reason();
      EXPECT_EQ(res->imu.p_IinG, ref->imu.p_IinG);
      EXPECT_EQ(res->imu.q_ItoG.coeffs(), ref->imu.q_ItoG.coeffs());
    }
  }
  MotionAligner with_heights(MotionAlignerOptions{}, tags);
  feed(with_heights, f, 40.0, 52.0, {101, 102, 103, 104}, 0.1, nullptr);
  with_heights.addHeight({Timestamp::fromSec(45.0), 3.0, 0.05});
  EXPECT_FALSE(with_heights.checkGravityDirection(Eigen::Vector3d::Zero()));
  EXPECT_NE(with_heights.reason().find("heights"), std::string::npos) << with_heights.reason();
}

TEST(MotionAligner, ALargeGyroBiasIsIntegratedAgainNotLeftToFirstOrder) {
  // A consumer gyro's bias of 0.02 rad/s (2σ of its prior) turns the attitude by 14° over a 12 s
  // window; the increments' first-order correction in δb_ω is then far off. Noise-free, and no
  // prior pull on the bias, so the answer is exact.
  Flight f(0.0, 0.0);
  const Eigen::Vector3d b_gyro(0.016, -0.01, 0.006);
  for (ImuSample& s : f.imu) s.gyro_rad_s += b_gyro;
  auto align = [&](double relinearize_rad) {
    MotionAlignerOptions o;
    o.sigma_bias_gyro_rad_s = 1.0;  // no pull towards 0: the data alone
    o.relinearize_rad = relinearize_rad;
    MotionAligner a(o, {{100, sim::PaperScenario::paper().tags_p_TinI.at(100)}});
    feed(a, f, 40.0, 40.0 + o.window_s, {101, 102, 103, 104}, 0.05, nullptr);
    auto res = a.solve(Eigen::Vector3d::Zero());
    return std::make_pair(res, a.relinearizations());
  };
  const auto [first_order, n0] = align(0.0);
  const auto [again, n1] = align(MotionAlignerOptions{}.relinearize_rad);
  EXPECT_EQ(n0, 0);
  EXPECT_GE(n1, 1);
  ASSERT_TRUE(again);
  const sim::TrajectoryState st = f.trajectory.evaluate(again->t.sec());
  // Integrated again: exact (measured 2e-5 m, 3e-6 rad/s).
  EXPECT_LT((again->imu.p_IinG - st.p_IinG).norm(), 1e-3);
  EXPECT_LT((again->imu.bias_gyro_rad_s - b_gyro).norm(), 1e-4);
  // First order only: refused, or off (measured 0.042 m, and a bias 0.035 rad/s off, more than
  // the bias itself).
  if (first_order) {
    EXPECT_GT((first_order->imu.p_IinG - st.p_IinG).norm(), 0.02);
    EXPECT_GT((first_order->imu.bias_gyro_rad_s - b_gyro).norm(), 0.01);
  }
}
