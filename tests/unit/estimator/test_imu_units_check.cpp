/// ImuUnitsCheck (estimator/imu/imu_units_check.h) and the node's reaction: an IMU stream in g or
/// deg/s stops the estimator with the reason instead of an estimate tens of metres off with exit 0
/// (issue 36).
#include <gtest/gtest.h>

#include <cmath>

#include "estimator/imu/imu_units_check.h"
#include "estimator/node/estimator_node.h"
#include "estimator/testing/synthetic_scenario.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

/// 200 Hz: specific force `f` [m/s²] and a rate turning about z at `rate` [rad/s], scaled by
/// `acc_scale` and `gyro_scale` (the units the stream is in).
std::vector<ImuSample> stream(double seconds, double rate, double acc_scale, double gyro_scale) {
  std::vector<ImuSample> out;
  for (int k = 0; k <= static_cast<int>(seconds * 200); ++k) {
    ImuSample s;
    s.t = Timestamp::fromSec(k / 200.0);
    s.acc_m_s2 = Eigen::Vector3d(0.3 * std::sin(k / 20.0), 0.1, 9.81) * acc_scale;
    s.gyro_rad_s = Eigen::Vector3d(0.0, 0.0, rate) * gyro_scale;
    out.push_back(s);
  }
  return out;
}

std::string firstFault(const std::vector<ImuSample>& samples) {
  ImuUnitsCheck check(ImuUnitsCheck::Options{});
  for (const ImuSample& s : samples)
    if (std::string f = check.add(s); !f.empty()) return f;
  return "";
}

}  // namespace

TEST(ImuUnitsCheck, MetresPerSecondSquaredAndRadiansPerSecondPass) {
  EXPECT_EQ(firstFault(stream(10.0, 0.0, 1.0, 1.0)), "");
  EXPECT_EQ(firstFault(stream(10.0, 3.0, 1.0, 1.0)), "");  // a fast turn, 170 deg/s for 10 s
}

TEST(ImuUnitsCheck, AnAccelerometerInGIsNamed) {
  const std::string f = firstFault(stream(3.0, 0.0, 1.0 / 9.81, 1.0));
  EXPECT_NE(f.find("mean |f| of 1.00"), std::string::npos) << f;
  EXPECT_NE(f.find("in g, not m/s^2?"), std::string::npos) << f;
  const std::string scaled = firstFault(stream(3.0, 0.0, 100.0, 1.0));  // cm/s², say
  EXPECT_NE(scaled.find("not in m/s^2, or scaled"), std::string::npos) << scaled;
}

TEST(ImuUnitsCheck, AGyroInDegreesPerSecondIsNamedOnceItTurns) {
  // At rest a gyro in deg/s reads its bias: nothing to tell. Turning at 0.5 rad/s it reads 28.6.
  EXPECT_EQ(firstFault(stream(10.0, 0.0, 1.0, 180.0 / M_PI)), "");
  const std::string f = firstFault(stream(10.0, 0.5, 1.0, 180.0 / M_PI));
  EXPECT_NE(f.find("median |w| of 28.6"), std::string::npos) << f;
  EXPECT_NE(f.find("in deg/s, not rad/s?"), std::string::npos) << f;
}

TEST(ImuUnitsCheck, TheNodeStopsWithTheReasonAndAResetStartsItAgain) {
  synthetic::SyntheticOptions so;
  so.duration_s = 12.0;
  const Dataset ds = synthetic::makeSyntheticDataset(so);
  EstimatorNode ok(EstimatorOptions{}, ds.setup);
  for (const auto& in : mergeInTimeOrder(ds)) ok.onInput(in);
  ASSERT_TRUE(ok.initialized()) << ok.waitingFor();

  Dataset in_g = ds;
  for (ImuSample& s : in_g.imu) s.acc_m_s2 /= 9.81;
  EstimatorNode node(EstimatorOptions{}, in_g.setup);
  for (const auto& in : mergeInTimeOrder(in_g)) node.onInput(in);
  EXPECT_FALSE(node.initialized());
  EXPECT_NE(node.waitingFor().find("IMU: the accelerometer reads a mean |f| of 1.0"), std::string::npos)
      << node.waitingFor();
  EXPECT_EQ(node.status().counters.at("imu_units_implausible"), 1);
  EXPECT_FALSE(node.pose());
  // A Reset command (the bridge restarted with the right units) starts the check again.
  EstimatorCommand reset;
  reset.t = ds.imu.back().t;
  reset.action = EstimatorCommand::Action::Reset;
  node.onInput(reset);
  EXPECT_EQ(node.waitingFor().find("IMU:"), std::string::npos) << node.waitingFor();
}
