// CONTROL_CMD / CONTROL_STATUS conversions (controller/process/control_messages.h): a status
// round-trips through control_status_t; malformed messages are named, not used.
#include <gtest/gtest.h>

#include <cmath>

#include "controller/process/control_messages.h"

using namespace meshnav;
using namespace meshnav::controller;

TEST(ControlMessages, StatusRoundTrip) {
  ControlStatus s;
  s.t = Timestamp::fromSec(12.345);
  s.mode = ControlMode::Failsafe;
  s.phase = "waypoints";
  s.waypoint = 3;
  s.failsafe_reason = "POSE late";
  s.failsafe_events = 2;
  s.pose_age_s = 0.35;
  s.position_cov_trace_m2 = 0.02;
  s.setpoint.p_IinG = {1.0, -2.0, 2.2};
  s.setpoint.v_IinG = {0.5, 0.0, -0.1};
  s.setpoint.yaw_rad = 0.7;
  s.command.thrust_m_s2 = 9.7;
  s.command.w_IinI = {0.1, -0.2, 0.3};
  s.mission_complete = false;
  const control_status_t m = toLcm(s, 77, 1.5, 4.0);
  EXPECT_EQ(invalidReason(m), "");
  EXPECT_EQ(m.updates, 77);
  EXPECT_DOUBLE_EQ(m.jitter_p99_ms, 1.5);
  const ControlStatus b = fromLcm(m);
  EXPECT_EQ(b.t, s.t);
  EXPECT_EQ(b.mode, ControlMode::Failsafe);
  EXPECT_EQ(b.phase, "waypoints");
  EXPECT_EQ(b.waypoint, 3);
  EXPECT_EQ(b.failsafe_reason, "POSE late");
  EXPECT_EQ(b.failsafe_events, 2);
  EXPECT_EQ(b.setpoint.p_IinG, s.setpoint.p_IinG);
  EXPECT_EQ(b.setpoint.v_IinG, s.setpoint.v_IinG);
  EXPECT_EQ(b.command.w_IinI, s.command.w_IinI);
  EXPECT_DOUBLE_EQ(b.command.thrust_m_s2, 9.7);
}

TEST(ControlMessages, CommandCarriesItsTimeAndMode) {
  ControlCommand c;
  c.t = Timestamp::fromSec(3.0);
  c.thrust_m_s2 = 9.81;
  c.w_IinI = {0.0, 0.1, 0.0};
  const control_cmd_t m = toLcm(c, ControlMode::Landed);
  EXPECT_EQ(m.utime, 3'000'000);
  EXPECT_EQ(modeOf(m.mode), ControlMode::Landed);
  EXPECT_EQ(invalidReason(m), "");
}

TEST(ControlMessages, MalformedMessagesAreNamed) {
  control_cmd_t c{};
  c.mode = 9;
  EXPECT_NE(invalidReason(c).find("unknown mode"), std::string::npos);
  c.mode = 1;
  c.thrust_m_s2 = std::nan("");
  EXPECT_NE(invalidReason(c).find("not finite"), std::string::npos);
  c.thrust_m_s2 = -1.0;
  EXPECT_NE(invalidReason(c).find("negative"), std::string::npos);
  control_status_t s{};
  s.mode = -1;
  EXPECT_NE(invalidReason(s).find("unknown mode"), std::string::npos);
  s.mode = 0;
  s.setpoint_p_IinG[1] = INFINITY;
  EXPECT_NE(invalidReason(s).find("not finite"), std::string::npos);
}

TEST(ControlMessages, StatusFieldsForTheViewShowModeAndFailsafe) {
  ControlStatus s;
  s.t = Timestamp::fromSec(40.0);
  s.mode = ControlMode::Failsafe;
  s.failsafe_events = 1;
  s.failsafe_reason = "POSE late";
  s.pose_age_s = 0.42;
  const auto f = statusFields(toLcm(s, 8000, 1.25, 3.5));
  ASSERT_EQ(f.size(), 6u);
  EXPECT_EQ(f[0].first, "mode");
  EXPECT_EQ(f[0].second, "failsafe");
  EXPECT_EQ(f[1].second, "1 (last: POSE late)");
  EXPECT_EQ(f[2].second, "0.420 s old, cov trace 0.0000 m²");
  EXPECT_EQ(f[5].second, "8000 updates, jitter p99 1.25 ms, max 3.50 ms");
  s.mode = ControlMode::Flying;
  s.phase = "waypoints";
  s.waypoint = 2;
  s.pose_age_s = -1.0;
  const auto g = statusFields(toLcm(s, 10, -1.0, -1.0));
  EXPECT_EQ(g[0].second, "flying / waypoints to waypoint 3");
  EXPECT_EQ(g[2].second, "none yet");
  EXPECT_EQ(g[5].second, "10 updates");
}
