#include <gtest/gtest.h>

#include "sim/lawnmower_trajectory.h"
#include "trajectory_checks.h"

using namespace meshnav::sim;
using namespace meshnav::sim::test;

TEST(SimLawnmowerTrajectory, SurveysLanesAtConstantHeightAndReturnsToThePad) {
  const Hall hall = Hall::ofSize({12.0, 8.0, 5.0});
  const LawnmowerTrajectory tr(hall, 140.0, 3);
  const double T = tr.duration();
  // During the pattern: constant height, lanes along x (the long axis) reversing direction.
  int reversals = 0;
  double last_vx = 0.0, z_min = 1e9, z_max = -1e9, x_span_min = 1e9, x_span_max = -1e9;
  for (double t = 0.2 * T; t < 0.75 * T; t += 0.05) {
    const auto s = tr.evaluate(t);
    z_min = std::min(z_min, s.p_IinG.z()), z_max = std::max(z_max, s.p_IinG.z());
    x_span_min = std::min(x_span_min, s.p_IinG.x()), x_span_max = std::max(x_span_max, s.p_IinG.x());
    if (std::abs(s.v_IinG.x()) > 0.3) {
      if (last_vx * s.v_IinG.x() < 0.0) ++reversals;
      last_vx = s.v_IinG.x();
    }
  }
  EXPECT_LT(z_max - z_min, 1e-9);
  EXPECT_GE(reversals, 2);
  EXPECT_GT(x_span_max - x_span_min, 0.7 * 12.0);
  EXPECT_LT((tr.evaluate(0.0).p_IinG - tr.evaluate(tr.duration()).p_IinG).norm(), 1e-9);
  EXPECT_TRUE(tr.isLanded(0.0) && tr.isLanded(tr.duration()));
}
