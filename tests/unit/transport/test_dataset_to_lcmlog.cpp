// dataset_to_lcmlog on a small dataset written here: every sample becomes one event, time-sorted,
// event timestamp = data utime, decodable as the channel's type.
#include <gtest/gtest.h>

#include <lcm/lcm-cpp.hpp>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "common/dataset.h"
#include "tests/support/test_util.h"
#include "transport/channels.h"
#include "transport/convert.h"

using namespace meshnav;
namespace fs = std::filesystem;

namespace {

/// A private temp folder of this test binary, removed at exit.
const meshnav::test::TempDir& tempRoot() {
  static const meshnav::test::TempDir root("d2l");
  return root;
}

/// A fresh folder for a test's dataset.
fs::path freshDir(const std::string& name) {
  const fs::path dir = tempRoot() / name;
  fs::remove_all(dir);
  return dir;
}

/// An empty dataset with tag 100 and known anchor 101.
Dataset withTagAndAnchor() {
  Dataset ds;
  ds.setup.rel_tag_positions[100] = Eigen::Vector3d(0.1, 0, 0);
  ds.setup.abs_anchor_positions[101] = Eigen::Vector3d(1, 2, 3);
  return ds;
}

/// Writes `ds` into `dir` and converts it; the log's path, "" when dataset_to_lcmlog failed.
std::string convert(const Dataset& ds, const fs::path& dir, const std::string& more_args = "") {
  writeDataset(ds, dir.string());
  const std::string log_path = (dir / "seq.lcmlog").string();
  const std::string cmd =
      std::string(DATASET_TO_LCMLOG) + " --dataset " + dir.string() + " --out " + log_path + more_args;
  return std::system(cmd.c_str()) == 0 ? log_path : std::string();
}

}  // namespace

TEST(DatasetToLcmlog, WritesEverySampleTimeSorted) {
  const fs::path dir = freshDir("meshnav_d2l");
  Dataset ds = withTagAndAnchor();
  for (int i = 0; i < 20; ++i) ds.imu.push_back({Timestamp{i * 5000}, {0, 0, 9.81}, {0, 0, 0}});
  for (int i = 0; i < 2; ++i) ds.baro.push_back({Timestamp{i * 50000 + 1}, 101300.0});
  ds.flight_states.push_back({Timestamp{0}, true});
  for (int i = 0; i < 3; ++i) {
    RangeSample r;
    r.t = Timestamp{i * 30000 + 7};
    r.id_initiator = 100;
    r.id_responder = 101;
    r.range_m = 2.0 + i;
    ds.ranges.push_back(r);
  }
  for (int i = 0; i < 4; ++i) ds.ground_truth.push_back({Timestamp{i * 16667}, {0, 0, 0}, Eigen::Quaterniond::Identity()});
  const std::string log_path = convert(ds, dir);
  ASSERT_FALSE(log_path.empty());

  lcm::LogFile log(log_path, "r");
  ASSERT_TRUE(log.good());
  std::map<std::string, int> counts;
  int64_t last = std::numeric_limits<int64_t>::min();
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    EXPECT_GE(ev->timestamp, last);
    last = ev->timestamp;
    ++counts[ev->channel];
    if (ev->channel == channels::kRange.name) {
      meshnav::range_t m;
      ASSERT_GT(m.decode(ev->data, 0, ev->datalen), 0);
      EXPECT_EQ(m.utime, ev->timestamp);  // event time = data time
      EXPECT_EQ(m.id_responder, 101);
    }
  }
  EXPECT_EQ(counts["IMU"], 20);
  EXPECT_EQ(counts["BARO"], 2);
  EXPECT_EQ(counts["FLIGHT_STATE"], 1);
  EXPECT_EQ(counts["RANGE"], 3);
  EXPECT_EQ(counts["GROUND_TRUTH"], 4);
  fs::remove_all(dir);
}

// --channel-prefix P: the log of vehicle P of a fleet, every channel named P/NAME (docs/channels.md).
TEST(DatasetToLcmlog, ChannelPrefixNamesEveryChannelForTheVehicle) {
  const fs::path dir = freshDir("meshnav_d2l_prefix");
  Dataset ds = withTagAndAnchor();
  ds.imu.push_back({Timestamp{0}, {0, 0, 9.81}, {0, 0, 0}});
  RangeSample r;
  r.t = Timestamp{7};
  r.id_initiator = 100;
  r.id_responder = 101;
  r.range_m = 2.0;
  ds.ranges.push_back(r);
  ds.ground_truth.push_back({Timestamp{0}, {0, 0, 0}, Eigen::Quaterniond::Identity()});
  const std::string log_path = convert(ds, dir, " --channel-prefix UAV1");
  ASSERT_FALSE(log_path.empty());
  lcm::LogFile log(log_path, "r");
  ASSERT_TRUE(log.good());
  std::vector<std::string> names;
  while (const lcm::LogEvent* ev = log.readNextEvent()) names.push_back(ev->channel);
  EXPECT_EQ(names, (std::vector<std::string>{"UAV1/IMU", "UAV1/GROUND_TRUTH", "UAV1/RANGE"}));
  EXPECT_TRUE(convert(ds, dir, " --channel-prefix UAV/1 2>/dev/null").empty());  // refused
  fs::remove_all(dir);
}

// At equal times the log keeps the estimator's canonical order (flight state, IMU, baro, range),
// the truth after those inputs and the height last: a replay causes no rewinds.
TEST(DatasetToLcmlog, EqualTimesKeepTheCanonicalOrder) {
  const fs::path dir = freshDir("meshnav_d2l_order");
  Dataset ds = withTagAndAnchor();
  const Timestamp t{10000};
  ds.heights.push_back({t, 1.5});
  ds.ground_truth.push_back({t, {0, 0, 0}, Eigen::Quaterniond::Identity()});
  RangeSample r;
  r.t = t;
  r.id_initiator = 100;
  r.id_responder = 101;
  r.range_m = 2.0;
  ds.ranges.push_back(r);
  ds.baro.push_back({t, 101300.0});
  ds.imu.push_back({t, {0, 0, 9.81}, {0, 0, 0}});
  ds.flight_states.push_back({t, true});
  const std::string log_path = convert(ds, dir);
  ASSERT_FALSE(log_path.empty());
  lcm::LogFile log(log_path, "r");
  ASSERT_TRUE(log.good());
  std::vector<std::string> order;
  while (const lcm::LogEvent* ev = log.readNextEvent()) order.push_back(ev->channel);
  EXPECT_EQ(order, (std::vector<std::string>{channels::kFlightState.name, channels::kImu.name, channels::kBaro.name,
                                             channels::kRange.name, channels::kGroundTruth.name, channels::kHeight.name}));
  fs::remove_all(dir);
}

TEST(DatasetToLcmlog, MissingDatasetFails) {
  const std::string cmd = std::string(DATASET_TO_LCMLOG) + " --dataset /nonexistent/x --out " + (tempRoot() / "x.lcmlog").string() + " 2>/dev/null";
  EXPECT_NE(std::system(cmd.c_str()), 0);
}
