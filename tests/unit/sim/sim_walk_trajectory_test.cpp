#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "sim/walk_trajectory.h"
#include "trajectory_checks.h"

using namespace meshnav::sim;
using namespace meshnav::sim::test;

namespace {
constexpr double kRadToDeg = 180.0 / std::numbers::pi;
}

TEST(SimWalkTrajectory, StaysInsideEveryHallAtHandHeight) {
  for (const Hall& hall : testHalls())
    for (uint64_t seed : {1u, 2u, 3u})
      for (double duration : {60.0, 140.0}) {
        const WalkTrajectory tr(hall, duration, seed);
        EXPECT_GT(clearance(tr, hall).walls_m, 0.5) << hall.toString() << " seed " << seed;
        for (double t = 0.0; t <= duration; t += 0.05) {
          const double z = tr.evaluate(t).p_IinG.z();
          ASSERT_GE(z, 0.9) << "t " << t;
          ASSERT_LE(z, 1.5) << "t " << t;
        }
      }
}

TEST(SimWalkTrajectory, NoTakeOffNoLandedStateNoBarometer) {
  const WalkTrajectory tr(Hall::paper(), 90.0, 3);
  EXPECT_FALSE(tr.hasLandedPhase());
  EXPECT_FALSE(tr.hasBarometer());
  EXPECT_EQ(tr.kind(), "walk");
  for (double t = 0.0; t <= tr.duration(); t += 0.5) EXPECT_FALSE(tr.isLanded(t)) << "t " << t;
}

TEST(SimWalkTrajectory, HeadingFollowsTheWalkWithSmallSwayAndStepsAtAboutTwoHertz) {
  const WalkTrajectory tr(Hall::paper(), 140.0, 4);
  int n_walking = 0, crossings = 0;
  double max_tilt_deg = 0.0, max_heading_err_deg = 0.0, prev_az = 0.0, max_lateral = 0.0;
  const double t0 = 30.0, t1 = 90.0;
  for (double t = t0; t < t1; t += 0.01) {
    const auto s = tr.evaluate(t);
    const Eigen::Vector3d x_I = s.R_ItoG.col(0), z_I = s.R_ItoG.col(2);
    max_tilt_deg = std::max(max_tilt_deg, std::acos(std::clamp(z_I.z(), -1.0, 1.0)) * kRadToDeg);
    const Eigen::Vector2d v = s.v_IinG.head<2>();
    ASSERT_GT(v.norm(), 0.5) << "walking at t " << t;
    ++n_walking;
    const double err = std::abs(std::remainder(std::atan2(x_I.y(), x_I.x()) - std::atan2(v.y(), v.x()), 2 * std::numbers::pi));
    max_heading_err_deg = std::max(max_heading_err_deg, err * kRadToDeg);
    // Vertical acceleration sign changes: two per step.
    const double az = s.a_IinG.z();
    if (t > t0 && (az > 0) != (prev_az > 0)) ++crossings;
    prev_az = az;
    const Eigen::Vector3d f_I = s.R_ItoG.transpose() * (s.a_IinG + Eigen::Vector3d(0, 0, Trajectory::kGravity_m_s2));
    max_lateral = std::max(max_lateral, std::abs(f_I.y()));
  }
  EXPECT_GT(n_walking, 5000);
  EXPECT_LT(max_tilt_deg, 10.0);   // a hand-held rig sways, it does not bank like a quadrotor
  EXPECT_GT(max_tilt_deg, 1.0);
  EXPECT_LT(max_heading_err_deg, 10.0);
  const double step_hz = 0.5 * crossings / (t1 - t0);
  EXPECT_NEAR(step_hz, 1.8, 0.25);
  EXPECT_GT(max_lateral, 0.1);  // lateral specific force: not a quadrotor (whose f_I is along z only)
}
