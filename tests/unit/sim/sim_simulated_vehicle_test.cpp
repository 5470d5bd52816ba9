// Step-wise sensor sampling (ImuSimulator::sample, BaroSimulator::sample,
// UwbRangeSimulator::simulateUntil) equals the batch simulators bit for bit, and the closed-loop
// vehicle (sim/simulated_vehicle.h) publishes its sensors at their rates.
#include <gtest/gtest.h>

#include <cmath>

#include "sim/baro_simulator.h"
#include "sim/imu_simulator.h"
#include "sim/paper_scenario.h"
#include "sim/simulated_vehicle.h"
#include "sim/spiral_trajectory.h"
#include "sim/tdma_schedule.h"
#include "sim/uwb_range_simulator.h"

using namespace meshnav;
using namespace meshnav::sim;

namespace {
SpiralTrajectory spiral() { return SpiralTrajectory(TrajectoryOptions::randomized(3, 1.0)); }
}  // namespace

TEST(StepwiseSensors, ImuEqualsBatch) {
  const SpiralTrajectory traj = spiral();
  ImuNoiseOptions o;
  o.scale_sigma = 0.01;
  ImuSimulator batch(o, 7), step(o, 7);
  const auto readings = batch.simulate(traj, 20.0);
  step.start(true);
  for (size_t k = 0; k < readings.size(); ++k) {
    const double t = static_cast<double>(k) * (1.0 / o.rate_hz);  // the batch's grid, bit for bit
    const ImuSample s = step.sample(traj.evaluate(t), !traj.isLanded(t));
    ASSERT_EQ(s.t, readings[k].t);
    ASSERT_EQ(s.acc_m_s2, readings[k].acc_m_s2) << k;
    ASSERT_EQ(s.gyro_rad_s, readings[k].gyro_rad_s) << k;
  }
  EXPECT_EQ(step.finalAccBias(), batch.finalAccBias());
}

TEST(StepwiseSensors, BaroEqualsBatch) {
  const SpiralTrajectory traj = spiral();
  BaroOptions o;
  BaroSimulator batch(o, 5), step(o, 5);
  const auto readings = batch.simulate(traj, 10.0);
  for (size_t k = 0; k < readings.size(); ++k) {
    const BaroSample s = step.sample(traj.evaluate(static_cast<double>(k) * (1.0 / o.rate_hz)));
    ASSERT_EQ(s.t, readings[k].t);
    ASSERT_EQ(s.pressure_pa, readings[k].pressure_pa) << k;
  }
}

TEST(StepwiseSensors, RangesInChunksEqualBatch) {
  const SpiralTrajectory traj = spiral();
  const PaperScenario sc = PaperScenario::paper();
  const TdmaSchedule schedule(sc.uwbDeviceIds(), 0.01, 0.0042);
  const UwbHardwareBiases biases(sc.uwbDeviceIds(), UwbHardwareOptions{});
  UwbRangeOptions o;
  o.correlation_time_s = 0.5;
  o.outlier_fraction = 0.1;
  UwbRangeSimulator batch(sc, biases, o, 9), step(sc, biases, o, 9);
  const auto all = batch.simulate(traj, schedule, 12.0);
  std::vector<SimulatedRange> chunks;
  const auto at = [&](double t) { return traj.evaluate(t); };
  for (double t = 0.0; t <= 12.0 + 1e-12; t += 0.001) {
    const auto part = step.simulateUntil(at, schedule, t);
    chunks.insert(chunks.end(), part.begin(), part.end());
  }
  ASSERT_EQ(chunks.size(), all.size());
  for (size_t i = 0; i < all.size(); ++i) {
    ASSERT_EQ(chunks[i].sample.t, all[i].sample.t);
    ASSERT_EQ(chunks[i].sample.range_m, all[i].sample.range_m) << i;
    ASSERT_EQ(chunks[i].outlier, all[i].outlier);
  }
  EXPECT_EQ(step.slotCount(), batch.slotCount());
  EXPECT_EQ(step.outlierCount(), batch.outlierCount());
  EXPECT_GT(batch.outlierCount(), 0);
}

TEST(SimulatedVehicle, OnThePadPublishesEverySensorAtItsRate) {
  SimulatedVehicleOptions o;
  o.sensors.seed = 4;
  o.pad_p_m = {0.5, -1.5, 0.0};
  o.pad_yaw_rad = 0.4;
  SimulatedVehicle v(o);
  VehicleOutputs all = v.start();
  for (int k = 0; k < 2000; ++k) {  // 2 s at 1 kHz
    VehicleOutputs out = v.step();
    all.imu.insert(all.imu.end(), out.imu.begin(), out.imu.end());
    all.baro.insert(all.baro.end(), out.baro.begin(), out.baro.end());
    all.ranges.insert(all.ranges.end(), out.ranges.begin(), out.ranges.end());
    all.flight_states.insert(all.flight_states.end(), out.flight_states.begin(), out.flight_states.end());
    all.truth.insert(all.truth.end(), out.truth.begin(), out.truth.end());
  }
  EXPECT_EQ(all.imu.size(), 401u);          // 200 Hz over [0, 2]
  EXPECT_EQ(all.truth.size(), 401u);
  EXPECT_EQ(all.baro.size(), 101u);         // 50 Hz
  EXPECT_EQ(all.flight_states.size(), 21u); // 10 Hz
  EXPECT_NEAR(static_cast<double>(all.ranges.size()), 200.0 * 0.98, 15.0);  // 100 slots/s, 2 % dropped
  for (const auto& f : all.flight_states) EXPECT_TRUE(f.landed);
  for (size_t k = 1; k < all.imu.size(); ++k) EXPECT_EQ((all.imu[k].t - all.imu[k - 1].t).us, 5000);
  // At rest, level: the accelerometer reads +g along z (plus bias and noise), no rotor vibration.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& s : all.imu) mean += s.acc_m_s2 / static_cast<double>(all.imu.size());
  EXPECT_NEAR(mean.z(), 9.81, 0.3);
  EXPECT_NEAR(mean.head<2>().norm(), 0.0, 0.3);
  // The setup's pad prior is drawn around the pad; the known anchors only.
  ASSERT_TRUE(v.setup().initial_pose.has_value());
  EXPECT_LT((v.setup().initial_pose->p_IinG - v.pad()).norm(), 0.3);
  EXPECT_EQ(v.setup().abs_anchor_positions.size(), 4u);
  EXPECT_EQ(v.truth().anchor_positions.size(), 9u);
  EXPECT_NEAR(all.truth.back().p_IinG.z(), o.dynamics.pad_height_m, 1e-12);
}

TEST(SimulatedVehicle, RefusesAnImuRateThatDoesNotDivideTheStep) {
  SimulatedVehicleOptions o;
  o.sensors.imu.rate_hz = 300.0;
  EXPECT_THROW(SimulatedVehicle v(o), std::invalid_argument);
}
