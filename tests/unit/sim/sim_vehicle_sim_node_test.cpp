// VehicleSimNode (sim/vehicle_sim_node.h): the lock-step handshake (an IMU step awaits the command
// stamped with it; a late one is counted and the last command kept; an older one is ignored),
// the sensor rates through the sinks, and the end of the flight.
#include <gtest/gtest.h>

#include "sim/vehicle_sim_node.h"

using namespace meshnav;
using namespace meshnav::sim;

namespace {

struct Counts {
  int imu = 0, baro = 0, ranges = 0, flight = 0, truth = 0;
};

VehicleSimSinks countingSinks(Counts& c, Timestamp* last_imu) {
  VehicleSimSinks s;
  s.imu = [&c, last_imu](const ImuSample& m) {
    ++c.imu;
    *last_imu = m.t;
  };
  s.baro = [&c](const BaroSample&) { ++c.baro; };
  s.range = [&c](const RangeSample&) { ++c.ranges; };
  s.flight_state = [&c](const FlightStateSample&) { ++c.flight; };
  s.truth = [&c](const PoseSample&, bool) { ++c.truth; };
  return s;
}

}  // namespace

TEST(VehicleSimNode, EachImuStepAwaitsTheCommandStampedWithIt) {
  Counts c;
  Timestamp last_imu;
  VehicleSimNode node({}, countingSinks(c, &last_imu));
  node.start();
  ASSERT_TRUE(node.awaiting());
  EXPECT_EQ(*node.awaiting(), last_imu);
  node.onCommand(last_imu, {0.0, Eigen::Vector3d::Zero()}, false);
  EXPECT_FALSE(node.awaiting());
  // 1 kHz steps, IMU every 5th: four steps without, then one that awaits again.
  for (int k = 0; k < 4; ++k) {
    node.step();
    EXPECT_FALSE(node.awaiting()) << k;
  }
  node.step();
  ASSERT_TRUE(node.awaiting());
  EXPECT_EQ(node.awaiting()->us, 5000);
  // An older command does not answer it and is ignored; the late declaration keeps the last one.
  node.onCommand(Timestamp{0}, {0.0, Eigen::Vector3d::Zero()}, false);
  EXPECT_TRUE(node.awaiting());
  node.onCommand(Timestamp{-1}, {0.0, Eigen::Vector3d::Zero()}, false);
  EXPECT_EQ(node.counters().commands_stale, 1);
  node.commandLate();
  EXPECT_FALSE(node.awaiting());
  EXPECT_EQ(node.counters().commands_late, 1);
}

TEST(VehicleSimNode, SensorRatesThroughTheSinks) {
  Counts c;
  Timestamp last_imu;
  VehicleSimNode node({}, countingSinks(c, &last_imu));
  node.start();
  while (node.time() < 2.0 - 1e-9) node.step();
  EXPECT_EQ(c.imu, 401);      // 200 Hz over [0, 2] s
  EXPECT_EQ(c.truth, 401);    // the truth at every IMU instant
  EXPECT_EQ(c.baro, 101);     // 50 Hz
  EXPECT_EQ(c.flight, 21);    // 10 Hz
  EXPECT_GT(c.ranges, 100);   // the meshed TDMA
  EXPECT_EQ(node.counters().imu, 401);
}

TEST(VehicleSimNode, TheDrillsFaultsReachTheSinks) {
  VehicleSimNodeOptions o;
  o.faults.imu_gaps_s = {{0.5, 1.0}};
  o.faults.range_loss_fraction = 0.5;
  Counts c;
  Timestamp last_imu;
  VehicleSimNode node(o, countingSinks(c, &last_imu));
  node.start();
  while (node.time() < 2.0 - 1e-9) node.step();
  EXPECT_EQ(c.imu, 301);    // 100 samples of [0.5, 1.0) s lost
  EXPECT_EQ(c.truth, 401);  // the truth is not
  EXPECT_EQ(node.faults().imuDropped(), 100);
  EXPECT_GT(node.faults().rangesLost(), 0);
}

TEST(VehicleSimNode, EndsAfterTouchdownOrMaxDuration) {
  VehicleSimNodeOptions o;
  o.max_duration_s = 0.5;
  o.after_touchdown_s = 0.1;
  Counts c;
  Timestamp last_imu;
  VehicleSimNode node(o, countingSinks(c, &last_imu));
  node.start();
  node.onCommand(Timestamp{0}, {0.0, Eigen::Vector3d::Zero()}, true);  // the controller says landed
  while (!node.done()) node.step();
  EXPECT_EQ(node.endReason(), "landed");
  EXPECT_NEAR(node.time(), 0.1, 1.5e-3);
  VehicleSimNode other(o, countingSinks(c, &last_imu));
  other.start();
  while (!other.done()) other.step();
  EXPECT_EQ(other.endReason(), "max duration");
}
