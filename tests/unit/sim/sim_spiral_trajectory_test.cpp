#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "sim/paper_scenario.h"
#include "sim/spiral_trajectory.h"

using namespace meshnav::sim;

namespace {
SpiralTrajectory makeTrajectory(uint64_t seed) { return SpiralTrajectory(TrajectoryOptions::randomized(seed)); }

/// Rotation vector of R (Log map).
Eigen::Vector3d logSO3(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

/// Times that exercise every phase (landed, take-off, ramps, spirals, landing) and boundaries.
std::vector<double> probeTimes(const SpiralTrajectory& tr) {
  const auto& o = tr.options();
  std::vector<double> ts;
  for (double t = 0.37; t < tr.duration(); t += 3.1) ts.push_back(t);
  for (double b : {o.takeoff_start_s, o.spiral_start_s, o.spiral_end_s - o.spiral_ramp_s, o.spiral_end_s,
                   o.landing_start_s})
    for (double d : {-0.2, 0.2}) ts.push_back(b + d);
  return ts;
}
}  // namespace

TEST(SimSpiralTrajectory, VelocityAndAccelerationAreDerivativesOfPosition) {
  for (uint64_t seed : {1u, 2u, 7u}) {
    const auto tr = makeTrajectory(seed);
    const double h = 1e-4;
    for (double t : probeTimes(tr)) {
      const auto s = tr.evaluate(t), sp = tr.evaluate(t + h), sm = tr.evaluate(t - h);
      EXPECT_LT((s.v_IinG - (sp.p_IinG - sm.p_IinG) / (2 * h)).norm(), 1e-6) << "seed " << seed << " t " << t;
      EXPECT_LT((s.a_IinG - (sp.v_IinG - sm.v_IinG) / (2 * h)).norm(), 1e-6) << "seed " << seed << " t " << t;
      EXPECT_LT((s.a_IinG - (sp.p_IinG - 2 * s.p_IinG + sm.p_IinG) / (h * h)).norm(), 1e-4);
    }
  }
}

TEST(SimSpiralTrajectory, AngularRateMatchesAttitudeDerivative) {
  for (uint64_t seed : {1u, 4u, 11u}) {
    const auto tr = makeTrajectory(seed);
    const double h = 1e-4;
    for (double t : probeTimes(tr)) {
      const auto s = tr.evaluate(t), sp = tr.evaluate(t + h), sm = tr.evaluate(t - h);
      // ω_I ≈ Log(R(t−h)ᵀ R(t+h)) / 2h (body frame), α ≈ (ω(t+h) − ω(t−h)) / 2h.
      const Eigen::Vector3d w_num = logSO3(sm.R_ItoG.transpose() * sp.R_ItoG) / (2 * h);
      EXPECT_LT((s.w_IinI - w_num).norm(), 1e-6) << "seed " << seed << " t " << t;
      EXPECT_LT((s.alpha_IinI - (sp.w_IinI - sm.w_IinI) / (2 * h)).norm(), 1e-5) << "seed " << seed << " t " << t;
      // The quaternion and the rotation matrix agree and are orthonormal.
      EXPECT_LT((s.q_ItoG.toRotationMatrix() - s.R_ItoG).norm(), 1e-12);
      EXPECT_LT((s.R_ItoG.transpose() * s.R_ItoG - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    }
  }
}

TEST(SimSpiralTrajectory, BodyZAxisAlongThrustAndHeadingFollowsYaw) {
  const auto tr = makeTrajectory(5);
  for (double t : probeTimes(tr)) {
    const auto s = tr.evaluate(t);
    const Eigen::Vector3d thrust = s.a_IinG + Eigen::Vector3d(0, 0, SpiralTrajectory::kGravity_m_s2);
    EXPECT_LT((s.R_ItoG.col(2) - thrust.normalized()).norm(), 1e-12);
    // Heading: y_I is orthogonal to x_c = [cos ψ, sin ψ, 0], and x_I points forward along x_c.
    const Eigen::Vector3d x_c(std::cos(s.yaw_rad), std::sin(s.yaw_rad), 0.0);
    EXPECT_NEAR(s.R_ItoG.col(1).dot(x_c), 0.0, 1e-12);
    EXPECT_GT(s.R_ItoG.col(0).dot(x_c), 0.9);
  }
}

TEST(SimSpiralTrajectory, MotionIsContinuousAcrossPhaseBoundaries) {
  const auto tr = makeTrajectory(3);
  const auto& o = tr.options();
  const double e = 1e-7;
  for (double b : {o.takeoff_start_s, o.takeoff_start_s + o.takeoff_duration_s, o.spiral_start_s,
                   o.spiral_start_s + o.spiral_ramp_s, o.spiral_end_s - o.spiral_ramp_s, o.spiral_end_s,
                   o.landing_start_s, o.landing_start_s + o.landing_duration_s}) {
    const auto l = tr.evaluate(b - e), r = tr.evaluate(b + e);
    EXPECT_LT((l.a_IinG - r.a_IinG).norm(), 1e-5) << "boundary " << b;
    EXPECT_LT((l.w_IinI - r.w_IinI).norm(), 1e-5) << "boundary " << b;
    EXPECT_LT((l.alpha_IinI - r.alpha_IinI).norm(), 1e-4) << "boundary " << b;
  }
}

TEST(SimSpiralTrajectory, FlightStaysInTheHallClimbsToEightMetresAndLandsAtStart) {
  const PaperScenario sc = PaperScenario::paper();
  for (uint64_t seed = 1; seed <= 12; ++seed) {
    const auto tr = makeTrajectory(seed);
    EXPECT_GT(tr.duration(), 130.0);
    EXPECT_LT(tr.duration(), 150.0);
    double z_max = 0, min_anchor_dist = 1e9, speed_max = 0, tilt_max = 0;
    for (double t = 0; t <= tr.duration(); t += 0.05) {
      const auto s = tr.evaluate(t);
      for (int i = 0; i < 3; ++i) {
        ASSERT_GT(s.p_IinG[i], sc.hall_min_m[i] + (i < 2 ? 0.4 : 0.05)) << "seed " << seed << " t " << t;
        ASSERT_LT(s.p_IinG[i], sc.hall_max_m[i] - 0.2) << "seed " << seed << " t " << t;
      }
      for (const auto& [tag, p_TinI] : sc.tags_p_TinI)
        for (const auto& [id, p_AinG] : sc.anchors_p_AinG)
          min_anchor_dist = std::min(min_anchor_dist, (s.p_IinG + s.R_ItoG * p_TinI - p_AinG).norm());
      z_max = std::max(z_max, s.p_IinG.z());
      speed_max = std::max(speed_max, s.v_IinG.norm());
      tilt_max = std::max(tilt_max, std::acos(s.R_ItoG(2, 2)));
    }
    EXPECT_GT(z_max, 7.5) << "seed " << seed;
    EXPECT_LE(z_max, 8.0) << "seed " << seed;
    EXPECT_GT(min_anchor_dist, 0.3) << "seed " << seed;
    EXPECT_LT(speed_max, 3.0) << "seed " << seed;
    EXPECT_LT(tilt_max, 0.35) << "seed " << seed;
    // At rest on the same pad at start and end, level, 2 m reached after take-off.
    const auto s0 = tr.evaluate(0.0), s_end = tr.evaluate(tr.duration());
    EXPECT_LT((s0.p_IinG - s_end.p_IinG).norm(), 1e-9);
    EXPECT_LT((s0.p_IinG - tr.padPosition()).norm(), 1e-12);
    EXPECT_EQ(s0.v_IinG.norm(), 0.0);
    EXPECT_EQ(s_end.v_IinG.norm(), 0.0);
    EXPECT_LT(s0.w_IinI.norm(), 1e-15);
    EXPECT_NEAR(s0.R_ItoG(2, 2), 1.0, 1e-15);
    const auto& o = tr.options();
    EXPECT_NEAR(tr.evaluate(o.spiral_start_s).p_IinG.z(), o.hover_height_m, 1e-9);
  }
}

TEST(SimSpiralTrajectory, LandedAtStartAndEndOnly) {
  const auto tr = makeTrajectory(1);
  EXPECT_TRUE(tr.isLanded(0.0));
  EXPECT_TRUE(tr.isLanded(4.0));
  EXPECT_FALSE(tr.isLanded(tr.takeoffTime() + 0.5));
  EXPECT_FALSE(tr.isLanded(70.0));
  EXPECT_FALSE(tr.isLanded(tr.touchdownTime() - 0.5));
  EXPECT_TRUE(tr.isLanded(tr.touchdownTime() + 0.1));
  EXPECT_TRUE(tr.isLanded(tr.duration()));
  EXPECT_GT(tr.takeoffTime(), 4.0);
  EXPECT_GT(tr.duration() - tr.touchdownTime(), 4.0);
  // While landed the UAV does not move.
  EXPECT_EQ(tr.evaluate(1.0).p_IinG, tr.evaluate(tr.takeoffTime() - 0.01).p_IinG);
}

TEST(SimSpiralTrajectory, SeedsGiveDifferentButSimilarFlights) {
  const auto a = makeTrajectory(1), b = makeTrajectory(2);
  EXPECT_GT((a.evaluate(60.0).p_IinG - b.evaluate(60.0).p_IinG).norm(), 0.05);
  EXPECT_NE(a.options().theta0_rad, b.options().theta0_rad);
  const auto a2 = makeTrajectory(1);
  EXPECT_EQ(a.evaluate(60.0).p_IinG, a2.evaluate(60.0).p_IinG);
}

TEST(SimSpiralTrajectory, DurationScaleShortensTheFlight) {
  const SpiralTrajectory full(TrajectoryOptions::randomized(6, 1.0));
  const SpiralTrajectory short_(TrajectoryOptions::randomized(6, 0.5));
  EXPECT_NEAR(short_.duration(), 0.5 * full.duration(), 1e-9);
  EXPECT_LT((short_.evaluate(30.0).p_IinG - full.evaluate(60.0).p_IinG).norm(), 1e-9);
}

TEST(SimSpiralTrajectory, InconsistentOptionsAreRejected) {
  TrajectoryOptions o;
  o.landing_start_s = o.spiral_end_s - 1.0;
  EXPECT_THROW(SpiralTrajectory{o}, std::invalid_argument);
}
