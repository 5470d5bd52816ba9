// The imu_bridge's inputs: imu.csv, baro.csv, flight_state.csv of a dataset folder, bad rows
// dropped and counted, merged into one deterministic time line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "imu_bridge/inertial_streams.h"
#include "tests/support/test_util.h"

using namespace meshnav;
using namespace meshnav::imu;
namespace fs = std::filesystem;

namespace {

fs::path freshDir(const std::string& name) {
  static const test::TempDir root("imu");  // removed at exit
  const fs::path d = root / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

}  // namespace

TEST(InertialStreams, LoadsAndMergesWithBadRowsDropped) {
  const auto d = freshDir("all");
  std::ofstream(d / "imu.csv") << "t,lin_acc_x,lin_acc_y,lin_acc_z,ang_vel_x,ang_vel_y,ang_vel_z\n"
                                  "0.000,0,0,9.81,0,0,0\n"
                                  "0.005,0,0,9.81,0,0,nan\n"
                                  "0.010,0,0,9.80,0,0,0.01\n";
  std::ofstream(d / "baro.csv") << "t,pressure\n0.0,101325.0\n0.010,-5\n0.05,101324.5\n";
  std::ofstream(d / "flight_state.csv") << "t,landed\n0.0,1\n0.01,0\n";
  Diagnostics diag;
  const auto s = loadInertialStreams(d.string(), diag);
  EXPECT_EQ(s.imu.size(), 2u);
  EXPECT_EQ(s.baro.size(), 2u);
  EXPECT_EQ(s.flight_states.size(), 2u);
  EXPECT_EQ(diag.get("imu.csv:bad_value"), 1);
  EXPECT_EQ(diag.get("baro.csv:bad_value"), 1);
  const auto tl = s.timeline();
  ASSERT_EQ(tl.size(), s.size());
  // Equal times in the estimator's canonical order: t=0: FLIGHT_STATE, IMU, BARO;
  // t=0.01: FLIGHT_STATE then IMU; t=0.05: BARO.
  const std::vector<int> streams = {InertialStreams::kFlightStateStream, InertialStreams::kImuStream,
                                    InertialStreams::kBaroStream, InertialStreams::kFlightStateStream,
                                    InertialStreams::kImuStream, InertialStreams::kBaroStream};
  for (size_t i = 0; i < tl.size(); ++i) EXPECT_EQ(tl[i].stream, streams[i]) << i;
  EXPECT_DOUBLE_EQ(s.imu[tl[4].index].acc_m_s2.z(), 9.80);
  fs::remove_all(d);
}

TEST(InertialStreams, HeightsAreTheFourthStreamLastAtEqualTimes) {
  const auto d = freshDir("height");
  std::ofstream(d / "imu.csv") << "t,lin_acc_x,lin_acc_y,lin_acc_z,ang_vel_x,ang_vel_y,ang_vel_z\n"
                                  "0.000,0,0,9.81,0,0,0\n0.010,0,0,9.81,0,0,0\n";
  std::ofstream(d / "height.csv") << "t,range_m\n0.0,1.20\n0.005,-3\n0.010,1.21\n";
  Diagnostics diag;
  const auto s = loadInertialStreams(d.string(), diag);
  EXPECT_EQ(s.heights.size(), 2u);
  EXPECT_EQ(diag.get("height.csv:bad_value"), 1);
  const auto tl = s.timeline();
  ASSERT_EQ(tl.size(), 4u);
  const std::vector<int> streams = {InertialStreams::kImuStream, InertialStreams::kHeightStream,
                                    InertialStreams::kImuStream, InertialStreams::kHeightStream};
  for (size_t i = 0; i < tl.size(); ++i) EXPECT_EQ(tl[i].stream, streams[i]) << i;
  EXPECT_DOUBLE_EQ(s.heights[tl[3].index].range_m, 1.21);
  fs::remove_all(d);
}

TEST(InertialStreams, OnlyBaroIsEnough) {
  const auto d = freshDir("baro");
  std::ofstream(d / "baro.csv") << "t,pressure\n0.0,101325.0\n";
  Diagnostics diag;
  const auto s = loadInertialStreams(d.string(), diag);
  EXPECT_TRUE(s.imu.empty());
  EXPECT_EQ(s.baro.size(), 1u);
  fs::remove_all(d);
}

TEST(InertialStreams, NothingToReplayThrows) {
  const auto d = freshDir("empty");
  Diagnostics diag;
  EXPECT_THROW(loadInertialStreams(d.string(), diag), std::runtime_error);
  EXPECT_THROW(loadInertialStreams((d / "missing").string(), diag), std::runtime_error);
  fs::remove_all(d);
}

TEST(InertialStreams, UnknownColumnLayoutThrows) {
  const auto d = freshDir("badheader");
  std::ofstream(d / "imu.csv") << "time,ax,ay,az\n0,0,0,9.81\n";
  Diagnostics diag;
  EXPECT_THROW(loadInertialStreams(d.string(), diag), std::runtime_error);
  fs::remove_all(d);
}
