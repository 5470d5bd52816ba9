// ControlLoop (controller/control_loop.h): when the controller runs in a process fed by messages —
// once per POSE at its time, once per IMU sample only while no POSE answers it (none yet, or the
// newest older than pose_timeout_s), never twice for one time, never backwards.
#include <gtest/gtest.h>

#include <vector>

#include "controller/control_loop.h"

using namespace meshnav;
using namespace meshnav::controller;

namespace {

mission::FlightPlan onePointPlan() {
  mission::FlightPlan p;
  p.pad_xy_m = {0.0, 0.0};
  mission::Waypoint w;
  w.p_IinG = {1.0, 0.0, 1.0};
  p.waypoints.push_back(w);
  return p;
}

PoseEstimate poseAt(double t_s) {
  PoseEstimate e;
  e.t = Timestamp::fromSec(t_s);
  e.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.001;
  return e;
}

struct Fixture {
  ControllerNode node{ControllerOptions{}, onePointPlan()};
  std::vector<int64_t> answered;  ///< times of the commands [µs]
  ControlLoop loop{node, 0.3, [this](const ControlCommand& c) { answered.push_back(c.t.us); }};
};

}  // namespace

TEST(ControlLoop, AnswersEveryImuSampleBeforeTheFirstPose) {
  Fixture f;
  for (int k = 0; k < 5; ++k) f.loop.onImu(Timestamp::fromSec(0.005 * k));
  ASSERT_EQ(f.answered.size(), 5u);
  EXPECT_EQ(f.answered.back(), Timestamp::fromSec(0.02).us);
  EXPECT_EQ(f.loop.imuUpdates(), 5);
}

TEST(ControlLoop, WithPosesAnswersEachPoseAndNotItsImuSample) {
  Fixture f;
  for (int k = 0; k < 10; ++k) {
    const double t = 0.005 * k;
    f.loop.onImu(Timestamp::fromSec(t));
    f.loop.onPose(poseAt(t));
  }
  // The first IMU sample came before any POSE: answered on IMU; its POSE then is not newer.
  ASSERT_EQ(f.answered.size(), 10u);
  EXPECT_EQ(f.loop.imuUpdates(), 1);
  for (int k = 0; k < 10; ++k) EXPECT_EQ(f.answered[k], Timestamp::fromSec(0.005 * k).us) << k;
}

TEST(ControlLoop, ImuAnswersOnceThePoseIsOlderThanTheTimeout) {
  Fixture f;
  f.loop.onPose(poseAt(1.0));
  // Within the timeout a POSE may still come: no answer on IMU.
  f.loop.onImu(Timestamp::fromSec(1.1));
  f.loop.onImu(Timestamp::fromSec(1.3));
  EXPECT_EQ(f.answered.size(), 1u);
  // Beyond it the estimator is silent: the IMU sample is answered (the failsafe keeps flying).
  f.loop.onImu(Timestamp::fromSec(1.305));
  ASSERT_EQ(f.answered.size(), 2u);
  EXPECT_EQ(f.answered.back(), Timestamp::fromSec(1.305).us);
}

TEST(ControlLoop, NeverAnswersATimeTwiceOrBackwards) {
  Fixture f;
  f.loop.onPose(poseAt(2.0));
  f.loop.onPose(poseAt(2.0));   // the same POSE again (a re-run)
  f.loop.onPose(poseAt(1.99));  // an older one
  f.loop.onImu(Timestamp::fromSec(2.0));
  EXPECT_EQ(f.answered.size(), 1u);
  EXPECT_EQ(f.loop.updates(), 1);
}
