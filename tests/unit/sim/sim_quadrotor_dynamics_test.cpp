// QuadrotorDynamics (sim/quadrotor_dynamics.h): hover with the exact thrust, free fall, a yaw
// rate, the lags, drag, ground contact and crashes, gusts; the IMU of the dynamics.
#include <gtest/gtest.h>

#include <cmath>

#include "sim/imu_simulator.h"
#include "sim/quadrotor_dynamics.h"
#include "sim/trajectory.h"

using namespace meshnav;
using namespace meshnav::sim;

namespace {

constexpr double kG = Trajectory::kGravity_m_s2;

QuadrotorOptions noDrag() {
  QuadrotorOptions o;
  o.drag_per_s = 0.0;
  return o;
}

/// Airborne at p with zero velocity, level, thrust `T` both actual and commanded.
QuadrotorDynamics airborne(const QuadrotorOptions& o, const Eigen::Vector3d& p, double T) {
  QuadrotorDynamics d(o, p, 0.0);
  d.setState(p, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), T);
  d.setCommand({T, Eigen::Vector3d::Zero()});
  return d;
}

}  // namespace

TEST(QuadrotorDynamics, HoverHoldsWithExactThrust) {
  QuadrotorDynamics d = airborne(QuadrotorOptions{}, {0.0, 0.0, 2.0}, kG);
  d.stepUntil(10.0);
  const TrajectoryState s = d.state();
  EXPECT_NEAR(s.t_s, 10.0, 1e-9);
  EXPECT_FALSE(d.landed());
  EXPECT_FALSE(d.crashed());
  EXPECT_LT((s.p_IinG - Eigen::Vector3d(0.0, 0.0, 2.0)).norm(), 1e-9);
  EXPECT_LT(s.v_IinG.norm(), 1e-9);
  EXPECT_LT(s.a_IinG.norm(), 1e-9);
}

TEST(QuadrotorDynamics, FreeFallMatchesHalfGTSquared) {
  QuadrotorDynamics d = airborne(noDrag(), {0.0, 0.0, 6.0}, 0.0);
  d.stepUntil(1.0);
  const TrajectoryState s = d.state();
  EXPECT_NEAR(s.p_IinG.z(), 6.0 - 0.5 * kG * 1.0, 1e-9);
  EXPECT_NEAR(s.v_IinG.z(), -kG, 1e-9);
  EXPECT_NEAR(s.a_IinG.z(), -kG, 1e-12);
  EXPECT_NEAR(s.p_IinG.head<2>().norm(), 0.0, 1e-12);
}

TEST(QuadrotorDynamics, YawRateIntegratesExactly) {
  QuadrotorDynamics d(QuadrotorOptions{}, {0.0, 0.0, 2.0}, 0.0);
  const double rate = 0.5;  // rad/s
  d.setState({0.0, 0.0, 2.0}, Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(), {0.0, 0.0, rate}, kG);
  d.setCommand({kG, {0.0, 0.0, rate}});
  d.stepUntil(2.0);
  const TrajectoryState s = d.state();
  EXPECT_NEAR(s.yaw_rad, rate * 2.0, 1e-9);
  EXPECT_NEAR(s.R_ItoG(2, 2), 1.0, 1e-12);  // still level
  EXPECT_LT((s.p_IinG - Eigen::Vector3d(0.0, 0.0, 2.0)).norm(), 1e-9);
}

TEST(QuadrotorDynamics, LagsReachTheirCommandWithTheirTimeConstants) {
  QuadrotorOptions o = noDrag();
  QuadrotorDynamics d = airborne(o, {0.0, 0.0, 4.0}, kG);
  d.setCommand({kG + 2.0, {0.2, 0.0, 0.0}});
  d.stepUntil(o.thrust_time_constant_s);
  EXPECT_NEAR(d.thrust(), kG + 2.0 * (1.0 - std::exp(-1.0)), 1e-6);
  QuadrotorDynamics r = airborne(o, {0.0, 0.0, 4.0}, kG);
  r.setCommand({kG, {0.2, 0.0, 0.0}});
  r.stepUntil(o.rate_time_constant_s);
  EXPECT_NEAR(r.state().w_IinI.x(), 0.2 * (1.0 - std::exp(-1.0)), 1e-9);
}

TEST(QuadrotorDynamics, DragGivesTheTerminalSpeed) {
  QuadrotorOptions o;
  o.drag_per_s = 0.5;
  // A constant extra upward thrust of 1 m/s²: terminal climb speed 1 / k_d = 2 m/s.
  QuadrotorDynamics d = airborne(o, {0.0, 0.0, 1.0}, kG + 1.0);
  d.stepUntil(5.0);  // 2.5 time constants: still short of the ceiling at 8.2 m
  EXPECT_NEAR(d.state().v_IinG.z(), 2.0 * (1.0 - std::exp(-2.5)), 1e-6);
}

TEST(QuadrotorDynamics, RestsOnThePadUntilThrustExceedsGravity) {
  QuadrotorOptions o;
  QuadrotorDynamics d(o, {1.0, 2.0, 0.0}, 0.3);
  EXPECT_TRUE(d.landed());
  EXPECT_NEAR(d.state().p_IinG.z(), o.pad_height_m, 1e-12);
  d.setCommand({0.9 * kG, {0.5, 0.0, 0.0}});
  d.stepUntil(1.0);
  EXPECT_TRUE(d.landed());
  EXPECT_NEAR(d.state().p_IinG.z(), o.pad_height_m, 1e-12);
  EXPECT_NEAR(d.state().yaw_rad, 0.3, 1e-12);
  EXPECT_LT(d.state().w_IinI.norm(), 1e-12);
  d.setCommand({kG + 1.0, Eigen::Vector3d::Zero()});
  d.stepUntil(2.0);
  EXPECT_FALSE(d.landed());
  EXPECT_GT(d.state().p_IinG.z(), o.pad_height_m + 0.1);
}

TEST(QuadrotorDynamics, SoftTouchDownLandsAndHardOneCrashes) {
  QuadrotorOptions o;
  // Descends at about 0.3 m/s with drag (thrust g − 0.09): lands, not crashed.
  {
    QuadrotorDynamics d = airborne(o, {0.0, 0.0, 0.6}, kG - 0.09);
    d.stepUntil(20.0);
    EXPECT_FALSE(d.crashed());
    d.setCommand({0.0, Eigen::Vector3d::Zero()});
    d.stepUntil(21.0);
    EXPECT_TRUE(d.landed());
    EXPECT_NEAR(d.state().p_IinG.z(), o.pad_height_m, 1e-12);
  }
  // Motors off at 3 m: hits the floor at about 7 m/s.
  {
    QuadrotorDynamics d = airborne(o, {0.0, 0.0, 3.0}, 0.0);
    d.stepUntil(3.0);
    EXPECT_TRUE(d.crashed());
    EXPECT_EQ(d.crashReason(), "floor");
    EXPECT_GT(d.crashSpeed(), o.crash_speed_m_s);
  }
}

TEST(QuadrotorDynamics, WallHitFasterThanCrashSpeedCrashes) {
  QuadrotorOptions o = noDrag();
  QuadrotorDynamics d(o, {0.0, 0.0, 2.0}, 0.0);
  d.setState({2.5, 0.0, 2.0}, {2.0, 0.0, 0.0}, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), kG);
  d.setCommand({kG, Eigen::Vector3d::Zero()});
  d.stepUntil(1.0);
  EXPECT_TRUE(d.crashed());
  EXPECT_EQ(d.crashReason(), "wall");
  EXPECT_LE(d.state().p_IinG.x(), o.hall_max_m.x());
}

TEST(QuadrotorDynamics, GustsAreSeededAndBounded) {
  QuadrotorOptions o;
  o.gust_sigma_m_s = 0.5;
  QuadrotorDynamics a = airborne(o, {0.0, 0.0, 2.0}, kG), b = airborne(o, {0.0, 0.0, 2.0}, kG);
  QuadrotorDynamics c(o, {0.0, 0.0, 2.0}, 0.0, 2);
  a.stepUntil(3.0);
  b.stepUntil(3.0);
  c.stepUntil(3.0);
  EXPECT_EQ(a.wind(), b.wind());
  EXPECT_NE(a.wind(), c.wind());
  EXPECT_LT(a.wind().norm(), 10.0 * o.gust_sigma_m_s);
  EXPECT_GT(a.state().v_IinG.norm(), 0.0);  // the wind moves it
}

TEST(QuadrotorDynamics, ImuOfTheDynamicsEqualsIdealAndIntegratesBack) {
  // A manoeuvre: tilt and yaw with extra thrust. The IMU's specific force and rate are the ideal
  // reading of the state (f = Rᵀ(a − g), ω); strapdown of those readings at the step follows the truth.
  QuadrotorOptions o = noDrag();
  QuadrotorDynamics d = airborne(o, {0.0, 0.0, 3.0}, kG);
  d.setCommand({kG + 0.5, {0.2, -0.1, 0.3}});
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  const Eigen::Vector3d g_G(0.0, 0.0, -kG);
  for (int k = 0; k < 500; ++k) {
    const TrajectoryState s0 = d.state();
    const ImuSample imu = ImuSimulator::ideal(s0);
    EXPECT_LT((imu.acc_m_s2 - s0.R_ItoG.transpose() * (s0.a_IinG - g_G)).norm(), 1e-12);
    EXPECT_LT((imu.gyro_rad_s - s0.w_IinI).norm(), 1e-15);
    // The specific force along body z is the thrust (no drag).
    EXPECT_NEAR(imu.acc_m_s2.z(), d.thrust(), 1e-9);
    d.step();
    const TrajectoryState s1 = d.state();
    const ImuSample imu1 = ImuSimulator::ideal(s1);
    // Trapezoid of the readings rotated into G equals the dynamics' velocity step.
    v += 0.5 * d.stepSize() * ((s0.R_ItoG * imu.acc_m_s2 + g_G) + (s1.R_ItoG * imu1.acc_m_s2 + g_G));
    EXPECT_LT((v - s1.v_IinG).norm(), 1e-9);
  }
}

TEST(QuadrotorDynamics, OptionsRefuseUnknownKeysAndBadValues) {
  EXPECT_NO_THROW(QuadrotorOptions::fromYaml(YAML::Load("drag_per_s: 0.2"), "v.yaml"));
  EXPECT_THROW(QuadrotorOptions::fromYaml(YAML::Load("drag: 0.2"), "v.yaml"), std::runtime_error);
  EXPECT_THROW(QuadrotorOptions::fromYaml(YAML::Load("max_thrust_m_s2: 5"), "v.yaml"), std::runtime_error);
  EXPECT_NE(QuadrotorOptions{}.toString().find("drag_per_s"), std::string::npos);
}
