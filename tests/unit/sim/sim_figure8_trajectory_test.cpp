#include <gtest/gtest.h>

#include "sim/figure8_trajectory.h"
#include "trajectory_checks.h"

using namespace meshnav::sim;
using namespace meshnav::sim::test;

TEST(SimFigure8Trajectory, TakesOffFromAndLandsOnThePadAndCoversTheHall) {
  const Hall hall = Hall::ofSize({10.0, 8.0, 5.0});
  const Figure8Trajectory tr(hall, 120.0, 5);
  EXPECT_TRUE(tr.hasLandedPhase());
  EXPECT_TRUE(tr.isLanded(0.0));
  EXPECT_TRUE(tr.isLanded(tr.duration()));
  EXPECT_FALSE(tr.isLanded(0.5 * tr.duration()));
  const auto s0 = tr.evaluate(0.0), s1 = tr.evaluate(tr.duration());
  EXPECT_LT((s0.p_IinG - s1.p_IinG).norm(), 1e-9);
  EXPECT_LT(s0.v_IinG.norm() + s1.v_IinG.norm(), 1e-12);
  double x_min = 1e9, x_max = -1e9, y_min = 1e9, y_max = -1e9;
  for (double t = 0; t < tr.duration(); t += 0.1) {
    const auto p = tr.evaluate(t).p_IinG;
    x_min = std::min(x_min, p.x()), x_max = std::max(x_max, p.x());
    y_min = std::min(y_min, p.y()), y_max = std::max(y_max, p.y());
  }
  EXPECT_GT(x_max - x_min, 0.6 * 10.0);  // along the long axis
  EXPECT_GT(y_max - y_min, 0.4 * 8.0);
}
