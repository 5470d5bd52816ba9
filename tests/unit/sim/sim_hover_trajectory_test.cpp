#include <gtest/gtest.h>

#include "sim/hover_trajectory.h"
#include "trajectory_checks.h"

using namespace meshnav::sim;
using namespace meshnav::sim::test;

TEST(SimHoverTrajectory, StartsInTheAirNeverLandsAndDriftsLittle) {
  const HoverTrajectory tr(Hall::paper(), 140.0, 6);
  EXPECT_FALSE(tr.hasLandedPhase());
  EXPECT_TRUE(tr.hasBarometer());
  const Eigen::Vector3d p0 = tr.evaluate(0.0).p_IinG;
  double max_drift = 0.0, max_speed = 0.0;
  for (double t = 0.0; t <= tr.duration(); t += 0.1) {
    EXPECT_FALSE(tr.isLanded(t));
    const auto s = tr.evaluate(t);
    max_drift = std::max(max_drift, (s.p_IinG - p0).norm());
    max_speed = std::max(max_speed, s.v_IinG.norm());
  }
  EXPECT_GT(p0.z(), 1.0);
  EXPECT_LT(max_drift, 1.0);
  EXPECT_GT(max_drift, 0.05);  // it does drift
  EXPECT_LT(max_speed, 0.5);
}
