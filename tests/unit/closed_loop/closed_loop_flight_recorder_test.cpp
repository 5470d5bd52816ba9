// FlightRecorder (closed_loop/flight_recorder.h): the evaluation over LCM gives the metrics of
// computeMetrics from the truth, POSE and CONTROL_STATUS: errors only while airborne, tracking only
// in the take-off, legs and return, a heartbeat's repeated status is no new sample, a status without
// truth is counted, and the failsafe count comes from the last status.
#include <gtest/gtest.h>

#include <cmath>

#include "closed_loop/flight_recorder.h"

using namespace meshnav;
using namespace meshnav::closed_loop;

namespace {

controller::ControlStatus statusAt(double t_s, controller::ControlMode mode, const std::string& phase,
                                   const Eigen::Vector3d& sp) {
  controller::ControlStatus s;
  s.t = Timestamp::fromSec(t_s);
  s.mode = mode;
  s.phase = phase;
  s.setpoint.p_IinG = sp;
  return s;
}

PoseEstimate poseAt(double t_s, const Eigen::Vector3d& p) {
  PoseEstimate e;
  e.t = Timestamp::fromSec(t_s);
  e.p_IinG = p;
  return e;
}

}  // namespace

TEST(FlightRecorder, MetricsFromTruthPosesAndStatuses) {
  FlightRecorder rec(SystemSetup{}, Truth{}, Eigen::Vector3d(0.0, 0.0, 0.0));
  // A heartbeat before the flight: no truth yet, counted and not used.
  rec.onControlStatus(statusAt(0.0, controller::ControlMode::Idle, "", Eigen::Vector3d::Zero()));
  EXPECT_EQ(rec.statusesWithoutTruth(), 1);
  const Eigen::Vector3d up(0.0, 0.0, 1.0);
  for (int k = 0; k < 4; ++k) {
    const double t = 0.005 * k;
    const bool airborne = k > 0;
    rec.onTruth(Timestamp::fromSec(t), up, Eigen::Quaterniond::Identity(), airborne);
    // The estimate is 0.3 m off in x; on the pad (k = 0) that is not counted.
    rec.onPose(poseAt(t, up + Eigen::Vector3d(k == 0 ? 5.0 : 0.3, 0.0, 0.0)));
    // The setpoint 0.4 m off in y while on a leg; the landing is not tracked.
    const std::string phase = k == 3 ? "landing" : "waypoints";
    rec.onControlStatus(statusAt(t, controller::ControlMode::Flying, phase, up + Eigen::Vector3d(0.0, 0.4, 0.0)));
    // A heartbeat repeating the update: no new sample.
    rec.onControlStatus(statusAt(t, controller::ControlMode::Flying, phase, Eigen::Vector3d::Zero()));
  }
  controller::ControlStatus last = statusAt(0.02, controller::ControlMode::Landed, "", up);
  last.failsafe_events = 2;
  rec.onControlStatus(last);  // newer, without truth: no sample, but the latest status
  FlightEnd end;
  end.landed = true;
  end.p_end = Eigen::Vector3d(0.3, 0.4, 0.0);
  end.duration_s = 0.015;
  const ClosedLoopResult r = rec.finish(end);
  ASSERT_EQ(r.samples.size(), 4u);
  EXPECT_NEAR(r.metrics.estimation_rmse_m, 0.3, 1e-12);
  EXPECT_NEAR(r.metrics.max_estimation_error_m, 0.3, 1e-12);
  EXPECT_NEAR(r.metrics.tracking_rmse_m, 0.4, 1e-12);  // samples k = 1, 2 (k = 0 on the pad, k = 3 landing)
  EXPECT_NEAR(r.metrics.landed_within_m, 0.5, 1e-12);
  EXPECT_TRUE(r.metrics.landed);
  EXPECT_EQ(r.metrics.failsafe_events, 2);  // from the latest status
  EXPECT_EQ(rec.statusesWithoutTruth(), 2);
}

TEST(FlightRecorder, FailsafeEventsAndCompletionFromTheLastStatus) {
  FlightRecorder rec(SystemSetup{}, Truth{}, Eigen::Vector3d::Zero());
  rec.onTruth(Timestamp::fromSec(1.0), Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity(), false);
  controller::ControlStatus s = statusAt(1.0, controller::ControlMode::Landed, "", Eigen::Vector3d::Zero());
  s.failsafe_events = 3;
  s.mission_complete = true;
  rec.onControlStatus(s);
  const ClosedLoopResult r = rec.finish(FlightEnd{});
  EXPECT_EQ(r.metrics.failsafe_events, 3);
  EXPECT_TRUE(r.metrics.mission_complete);
  EXPECT_FALSE(r.metrics.landed);
  EXPECT_EQ(r.metrics.landed_within_m, -1.0);
}
