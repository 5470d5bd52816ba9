// ControllerNode (controller/controller_node.h) flying sim::QuadrotorDynamics on the TRUE pose
// (handed over as POSE with a small covariance): it converges to a hover, flies a plan and lands
// on the pad; a stale POSE triggers the failsafe, which descends and lands softly; a POSE that
// comes back resumes the plan; a large covariance triggers it too.
#include <gtest/gtest.h>

#include <cmath>

#include "controller/controller_node.h"
#include "sim/quadrotor_dynamics.h"

using namespace meshnav;
using namespace meshnav::controller;

namespace {

mission::FlightPlan squarePlan() {
  mission::FlightPlan p;
  p.pad_xy_m = {0.0, -1.0};
  p.takeoff_at_s = 1.0;
  p.takeoff_height_m = 1.5;
  for (const auto& q : {Eigen::Vector3d(1.0, -1.0, 1.5), Eigen::Vector3d(1.0, 1.0, 2.0), Eigen::Vector3d(-1.0, 1.0, 1.5)}) {
    mission::Waypoint w;
    w.p_IinG = q;
    w.yaw_deg = 45.0;
    p.waypoints.push_back(w);
  }
  return p;
}

/// The true state as a POSE stamped `t`.
PoseEstimate truePose(const sim::QuadrotorDynamics& d, double cov_trace_m2 = 0.003) {
  const sim::TrajectoryState s = d.state();
  PoseEstimate e;
  e.t = Timestamp::fromSec(s.t_s);
  e.p_IinG = s.p_IinG;
  e.v_IinG = s.v_IinG;
  e.q_ItoG = s.q_ItoG;
  e.cov_p_m2 = Eigen::Matrix3d::Identity() * cov_trace_m2 / 3.0;
  return e;
}

/// Flies at 200 Hz control / 1 kHz dynamics until `t_end` or landing; `pose_ok(t)` false withholds
/// POSE; `cov(t)` is the trace of the POSE's covariance. Returns the largest distance to the
/// setpoint while flying a leg (from 2 s after take-off).
struct Flight {
  sim::QuadrotorDynamics dyn{sim::QuadrotorOptions{}, {0.0, -1.0, 0.0}, 0.0};
  ControllerNode node;
  double max_track_m = 0.0;
  explicit Flight(const mission::FlightPlan& p, ControllerOptions o = {}) : node(o, p) {}
  template <class PoseOk, class Cov>
  void fly(double t_end, PoseOk pose_ok, Cov cov) {
    while (dyn.time() < t_end && !dyn.crashed()) {
      if (dyn.stepIndex() % 5 == 0) {
        const double t = dyn.time();
        if (pose_ok(t)) node.onPose(truePose(dyn, cov(t)));
        node.onFlightState({Timestamp::fromSec(t), dyn.landed()});
        const ControlCommand c = node.update(Timestamp::fromSec(t));
        dyn.setCommand({c.thrust_m_s2, c.w_IinI});
        const auto& st = node.status();
        if (st.mode == ControlMode::Flying && (st.phase == "waypoints" || st.phase == "return"))
          max_track_m = std::max(max_track_m, (dyn.state().p_IinG - st.setpoint.p_IinG).norm());
        if (node.mode() == ControlMode::Landed && dyn.landed()) break;
      }
      dyn.step();
    }
  }
  void fly(double t_end) {
    fly(t_end, [](double) { return true; }, [](double) { return 0.003; });
  }
};

}  // namespace

TEST(ControllerNode, ConvergesToAHoverFromAnOffset) {
  mission::FlightPlan p = squarePlan();
  p.waypoints.resize(1);
  p.waypoints[0].p_IinG = {0.0, -1.0, 1.5};
  p.waypoints[0].yaw_deg = 0.0;
  p.waypoints[0].hold_s = 30.0;
  Flight f(p);
  // Taken off (the spin-up is over), then pushed 0.5 m off, tilted, moving.
  f.fly(3.0);
  f.dyn.setState({0.5, -1.3, 1.0}, {0.3, 0.0, 0.0},
                 Eigen::AngleAxisd(0.2, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix(),
                 Eigen::Vector3d::Zero(), 9.81);
  f.fly(25.0);
  const sim::TrajectoryState s = f.dyn.state();
  EXPECT_FALSE(f.dyn.crashed());
  EXPECT_EQ(f.node.mode(), ControlMode::Flying);
  EXPECT_LT((s.p_IinG - Eigen::Vector3d(0.0, -1.0, 1.5)).norm(), 0.02);
  EXPECT_LT(s.v_IinG.norm(), 0.02);
  EXPECT_NEAR(s.R_ItoG(2, 2), 1.0, 1e-3);
  // The integral learnt the hover thrust (no drag at rest): g.
  EXPECT_NEAR(f.node.positionController().hoverThrust(), 9.81, 0.05);
}

TEST(ControllerNode, FliesThePlanAndLandsOnThePad) {
  Flight f(squarePlan());
  f.fly(120.0);
  EXPECT_FALSE(f.dyn.crashed());
  EXPECT_EQ(f.node.mode(), ControlMode::Landed);
  EXPECT_TRUE(f.node.status().mission_complete);
  EXPECT_TRUE(f.dyn.landed());
  EXPECT_LT((f.dyn.state().p_IinG.head<2>() - Eigen::Vector2d(0.0, -1.0)).norm(), 0.05);
  EXPECT_LT(f.max_track_m, 0.15);
  EXPECT_EQ(f.node.status().failsafe_events, 0);
  EXPECT_NEAR(f.dyn.state().yaw_rad, 0.0, 0.05);
}

TEST(ControllerNode, StalePoseTriggersFailsafeThatLandsSoftly) {
  Flight f(squarePlan());
  // POSE stops for good at 15 s (on the first leg, at 1.5 m).
  f.fly(200.0, [](double t) { return t < 15.0; }, [](double) { return 0.003; });
  EXPECT_FALSE(f.dyn.crashed()) << f.dyn.crashReason() << " at " << f.dyn.crashSpeed() << " m/s";
  EXPECT_TRUE(f.dyn.landed());
  EXPECT_EQ(f.node.mode(), ControlMode::Landed);
  EXPECT_FALSE(f.node.status().mission_complete);
  EXPECT_EQ(f.node.status().failsafe_events, 1);
  EXPECT_EQ(f.node.status().failsafe_reason, "POSE late");
  // It landed within a few seconds of descent, not far from where POSE stopped.
  EXPECT_LT(f.dyn.time(), 40.0);
}

TEST(ControllerNode, FailsafeRecoversWhenPoseComesBack) {
  Flight f(squarePlan());
  f.fly(200.0, [](double t) { return t < 15.0 || t > 16.5; }, [](double) { return 0.003; });
  EXPECT_FALSE(f.dyn.crashed());
  EXPECT_EQ(f.node.status().failsafe_events, 1);
  EXPECT_TRUE(f.node.status().mission_complete);
  EXPECT_LT((f.dyn.state().p_IinG.head<2>() - Eigen::Vector2d(0.0, -1.0)).norm(), 0.05);
}

TEST(ControllerNode, LargeCovarianceTriggersFailsafe) {
  Flight f(squarePlan());
  f.fly(200.0, [](double) { return true; }, [](double t) { return t < 15.0 ? 0.003 : 2.0; });
  EXPECT_FALSE(f.dyn.crashed());
  EXPECT_TRUE(f.dyn.landed());
  EXPECT_EQ(f.node.status().failsafe_reason, "POSE covariance too large");
  EXPECT_FALSE(f.node.status().mission_complete);
  // A fresh POSE keeps the attitude level during the descent: it lands close to where it was.
  EXPECT_LT(f.dyn.state().p_IinG.head<2>().norm(), 3.0);
}

TEST(ControllerNode, StaysOnThePadWithoutAPose) {
  Flight f(squarePlan());
  f.fly(10.0, [](double) { return false; }, [](double) { return 0.003; });
  EXPECT_EQ(f.node.mode(), ControlMode::Idle);
  EXPECT_TRUE(f.dyn.landed());
  EXPECT_EQ(f.node.status().command.thrust_m_s2, 0.0);
}

TEST(ControllerOptions, RefusesUnknownKeysAndBadValues) {
  EXPECT_NO_THROW(ControllerOptions::fromYaml(YAML::Load("kp_xy_per_s: 1.0"), "c.yaml"));
  EXPECT_THROW(ControllerOptions::fromYaml(YAML::Load("kp_xy: 1.0"), "c.yaml"), std::runtime_error);
  EXPECT_THROW(ControllerOptions::fromYaml(YAML::Load("max_tilt_deg: 95"), "c.yaml"), std::runtime_error);
  EXPECT_NE(ControllerOptions{}.toString().find("pose_timeout_s"), std::string::npos);
}

TEST(ControllerOptions, ShippedFileHoldsTheDefaults) {
  const ControllerOptions shipped = ControllerOptions::load(MESHNAV_SOURCE_DIR "/config/controller.yaml");
  EXPECT_EQ(shipped.toString(), ControllerOptions{}.toString());
}
