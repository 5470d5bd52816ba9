// WaypointFollower (controller/waypoint_follower.h): legs, speed profile, holds, landing.
#include <gtest/gtest.h>

#include <cmath>

#include "controller/waypoint_follower.h"
#include "mission/flight_plan.h"

using namespace meshnav;
using namespace meshnav::controller;

namespace {
mission::FlightPlan plan() {
  mission::FlightPlan p;
  p.pad_xy_m = {0.0, 0.0};
  p.takeoff_height_m = 1.0;
  p.speed_m_s = 0.5;
  p.vertical_speed_m_s = 0.25;
  p.acceleration_m_s2 = 0.5;
  p.yaw_rate_deg_s = 30.0;
  mission::Waypoint w;
  w.p_IinG = {2.0, 0.0, 1.0};
  w.yaw_deg = 90.0;
  w.hold_s = 1.0;
  p.waypoints.push_back(w);
  return p;
}
}  // namespace

TEST(WaypointFollower, FliesTakeOffLegReturnAndLanding) {
  WaypointFollower f(plan());
  f.start(10.0, {0.0, 0.0, 0.1}, 0.0);
  EXPECT_EQ(f.phase(), WaypointFollower::Phase::TakeOff);
  double max_speed_xy = 0.0, max_speed_z = 0.0;
  bool reached = false;
  Setpoint prev = f.setpoint(10.0);
  EXPECT_LT((prev.p_IinG - Eigen::Vector3d(0.0, 0.0, 0.1)).norm(), 1e-12);
  for (double t = 10.0; t < 60.0; t += 0.01) {
    const Setpoint sp = f.setpoint(t);
    max_speed_xy = std::max(max_speed_xy, sp.v_IinG.head<2>().norm());
    max_speed_z = std::max(max_speed_z, std::abs(sp.v_IinG.z()));
    // The position is continuous (no jumps between legs) while not landing.
    if (!f.landing()) {
      EXPECT_LT((sp.p_IinG - prev.p_IinG).norm(), 0.01 * 0.5 + 1e-9) << t;
    }
    if ((sp.p_IinG - Eigen::Vector3d(2.0, 0.0, 1.0)).norm() < 1e-9) {
      reached = true;
      EXPECT_NEAR(sp.yaw_rad, M_PI / 2, 1e-9);
    }
    prev = sp;
  }
  EXPECT_TRUE(reached);
  EXPECT_LE(max_speed_xy, 0.5 + 1e-12);
  EXPECT_LE(max_speed_z, 0.25 + 1e-12);
  EXPECT_TRUE(f.landing());
  const Setpoint land = f.setpoint(70.0);
  EXPECT_FALSE(land.hold_z);
  EXPECT_NEAR(land.v_IinG.z(), -0.25, 1e-12);
  EXPECT_LT(land.p_IinG.head<2>().norm(), 1e-12);  // above the pad
}

TEST(WaypointFollower, TrapezoidTimingOfALeg) {
  // 2 m at 0.5 m/s with 0.5 m/s² ramps: 2/0.5 + 0.5/0.5 = 5 s; the heading turn of 90° at 30°/s
  // (3 s) is shorter, so the leg lasts 5 s plus its 1 s hold.
  mission::FlightPlan p = plan();
  p.takeoff_height_m = 0.1;  // no climb: the take-off leg is only its settle hold (1 s)
  p.waypoints[0].p_IinG.z() = 0.1;
  WaypointFollower g(p);
  g.start(0.0, {0.0, 0.0, 0.1}, 0.0);
  g.setpoint(1.0 + 1e-9);  // the take-off leg is done
  EXPECT_EQ(g.phase(), WaypointFollower::Phase::Waypoints);
  EXPECT_NEAR(g.setpoint(1.0 + 2.5).p_IinG.x(), 1.0, 1e-9);   // half way at half time (symmetric)
  EXPECT_NEAR(g.setpoint(1.0 + 2.5).v_IinG.x(), 0.5, 1e-9);
  EXPECT_NEAR(g.setpoint(1.0 + 5.0).p_IinG.x(), 2.0, 1e-9);
  EXPECT_EQ(g.phase(), WaypointFollower::Phase::Waypoints);   // holding
  g.setpoint(1.0 + 6.0 + 1e-9);
  EXPECT_EQ(g.phase(), WaypointFollower::Phase::ReturnToPad);
}
