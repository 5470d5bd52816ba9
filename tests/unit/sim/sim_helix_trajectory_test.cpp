#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "sim/helix_trajectory.h"
#include "trajectory_checks.h"

using namespace meshnav::sim;
using namespace meshnav::sim::test;

TEST(SimHelixTrajectory, ClimbsToNearTheCeilingOfEveryHall) {
  for (const Hall& hall : testHalls())
    for (uint64_t seed : {1u, 2u, 3u}) {
      const HallClearance c = clearance(HelixTrajectory(hall, 90.0, seed), hall);
      EXPECT_GT(c.ceiling_m, 0.5) << hall.toString() << " seed " << seed;
      EXPECT_LT(c.ceiling_m, 1.3) << hall.toString() << " seed " << seed;  // the top of the helix
    }
}

TEST(SimHelixTrajectory, HeadingAlongTheCircleAndLandsWhereItTookOff) {
  const HelixTrajectory tr(Hall::paper(), 140.0, 4);
  int n_checked = 0;
  for (double t = 0.0; t < tr.duration(); t += 0.5) {
    const auto s = tr.evaluate(t);
    if (s.v_IinG.head<2>().norm() < 0.2) continue;
    const double course = std::atan2(s.v_IinG.y(), s.v_IinG.x());
    EXPECT_NEAR(std::remainder(s.yaw_rad - course, 2.0 * std::numbers::pi), 0.0, 1e-9) << "t " << t;
    ++n_checked;
  }
  EXPECT_GT(n_checked, 100);
  EXPECT_TRUE(tr.isLanded(1.0));
  EXPECT_FALSE(tr.isLanded(70.0));
  EXPECT_LT((tr.evaluate(0.0).p_IinG - tr.evaluate(tr.duration()).p_IinG).norm(), 1e-9);
}
