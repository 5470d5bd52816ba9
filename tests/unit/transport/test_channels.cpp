/// Typed channels (transport/channels.h): a channel carries its message type, so LcmNode's
/// publish/subscribe, the heartbeat of ProcessMain and the InputJournal accept only that type. The
/// negative checks are compile-time: each `requires` expression below is what a wrong pairing in
/// a process would be, and it must not be well-formed.
#include <gtest/gtest.h>

#include <functional>
#include <set>
#include <string>
#include <type_traits>

#include "estimator/node/estimator_input.h"
#include "transport/channels.h"
#include "transport/input_journal.h"
#include "transport/lcm_node.h"
#include "transport/process_main.h"

namespace meshnav::transport {
namespace {

template <class T, class Ch>
concept CanSubscribe = requires(LcmNode& n, Ch ch, std::function<void(const T&)> f) { n.subscribe(ch, f); };
template <class T, class Ch>
concept CanSubscribeExplicit =
    requires(LcmNode& n, Ch ch, std::function<void(const T&)> f) { n.template subscribe<T>(ch, f); };
template <class T, class Ch>
concept CanPublish = requires(LcmNode& n, Ch ch, const T& v) { n.publish(ch, v); };
template <class T, class Ch>
concept CanJournal = requires(InputJournal& j, Ch ch, const T& v) { j.write(ch, v, int64_t{0}); };
template <class T, class Ch>
concept CanHeartbeat = requires(ProcessMain& p, Ch ch, std::function<T()> f) { p.heartbeat(ch, 1.0, f); };

using Imu = decltype(channels::kImu);
using Baro = decltype(channels::kBaro);

// The right pairings compile ...
static_assert(CanSubscribe<ImuSample, Imu>);
static_assert(CanSubscribeExplicit<ImuSample, Imu>);
static_assert(CanPublish<ImuSample, Imu>);
static_assert(CanSubscribe<std::vector<AnchorEstimate>, decltype(channels::kAnchors)>);
static_assert(CanSubscribe<time_sync_t, decltype(channels::kTimeSync)>);  // an LCM type without plain struct
static_assert(CanJournal<RangeSample, decltype(channels::kRange)>);
static_assert(CanHeartbeat<EstimatorStatus, decltype(channels::kEstimatorStatus)>);

// ... the wrong ones do not: subscribe<ImuSample>(kBaro) was the example of issue 11.
static_assert(!CanSubscribe<ImuSample, Baro>);
static_assert(!CanSubscribeExplicit<ImuSample, Baro>);
static_assert(!CanPublish<ImuSample, Baro>);
static_assert(!CanPublish<PoseSample, decltype(channels::kPose)>);  // ground truth is not an estimate
static_assert(!CanPublish<imu_t, Imu>);                              // nor the LCM type past its conversion
static_assert(!CanJournal<PoseEstimate, decltype(channels::kRange)>);
static_assert(!CanHeartbeat<CalibStatus, decltype(channels::kEstimatorStatus)>);
// A bare name no longer selects a type: typed publish/subscribe take only a channel constant.
static_assert(!CanSubscribeExplicit<ImuSample, const char*>);
static_assert(!CanSubscribeExplicit<ImuSample, std::string>);
static_assert(!CanPublish<ImuSample, std::string>);
static_assert(!std::is_convertible_v<Baro, Imu>);

// channels::find: the constant of a type and a name, at compile time; none for a wrong type.
static_assert(std::string_view(channels::find<HeightSample>("HEIGHT").name) == channels::kHeight.name);
static_assert(channels::find<ImuSample>("BARO").name == nullptr);
static_assert(channels::find<ImuSample>("NO_SUCH").name == nullptr);

// Every input kind of the estimator (estimator/node/estimator_input.h) has a channel of its name
// and type, unless its table entry says `kDatasetOnly`: the estimator process subscribes it from
// that table.
TEST(Channels, EveryEstimatorInputKindHasItsChannel) {
  int n = 0;
  estimator::forEachInputKind([&]<class T>() {
    using K = estimator::InputKind<T>;
    if constexpr (requires { K::kDatasetOnly; }) return;
    constexpr auto c = channels::find<T>(K::name);
    EXPECT_NE(c.name, nullptr) << K::name;
    if (c.name) {
      EXPECT_STREQ(c.name, K::name);
    }
    ++n;
  });
  EXPECT_GE(n, 8);  // PEER_RANGE too since the peer router (issue 38)
}

TEST(Channels, NamesAreDistinctAndUpperSnake) {
  std::set<std::string> names;
  for (const char* n : channels::kAll) {
    const std::string s(n);
    EXPECT_TRUE(names.insert(s).second) << s << " twice";
    for (char c : s) EXPECT_TRUE((c >= 'A' && c <= 'Z') || c == '_') << s;
  }
  EXPECT_EQ(names.size(), 20u);
}

TEST(Channels, TypedRoundTripOverMemq) {
  LcmNode node("test", "memq://");
  std::vector<BaroSample> got;
  int imu = 0;
  node.subscribe(channels::kBaro, [&](const BaroSample& b) { got.push_back(b); });
  node.subscribe(channels::kImu, [&](const ImuSample&) { ++imu; });
  BaroSample b;
  b.t = Timestamp{1234};
  b.pressure_pa = 101000.0;
  ASSERT_TRUE(node.publish(channels::kBaro, b));
  while (node.spinOnce(0) > 0) {
  }
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].t, b.t);
  EXPECT_DOUBLE_EQ(got[0].pressure_pa, b.pressure_pa);
  EXPECT_EQ(imu, 0);
  EXPECT_EQ(node.received(channels::kBaro.name), 1);
}

// Vehicle prefixes (docs/channels.md): every channel but the fleet's shared ones goes on the wire
// as PREFIX/NAME; no prefix leaves every name as it is.
TEST(ChannelPrefix, PerVehicleChannelsArePrefixedAndSharedOnesNot) {
  EXPECT_EQ(channels::prefixed(channels::kPose, "UAV1"), "UAV1/POSE");
  EXPECT_EQ(channels::prefixed(channels::kImu, "v0"), "v0/IMU");
  EXPECT_EQ(channels::prefixed(channels::kRange, "v4"), "v4/RANGE");
  EXPECT_EQ(channels::prefixed(channels::kEstimatorStatus, "v0"), "v0/ESTIMATOR_STATUS");
  EXPECT_EQ(channels::prefixed(channels::kAnchorInit, "v0"), "v0/ANCHOR_INIT");  // the calibrator addresses one vehicle
  EXPECT_EQ(channels::prefixed(channels::kTimeSync, "v0"), "v0/TIME_SYNC");
  EXPECT_EQ(channels::prefixed(channels::kCalibCmd, "v0"), "CALIB_CMD");
  EXPECT_EQ(channels::prefixed(channels::kCalibStatus, "v0"), "CALIB_STATUS");
  EXPECT_EQ(channels::prefixed(channels::kMissionStatus, "v0"), "MISSION_STATUS");
  EXPECT_EQ(channels::prefixed(channels::kPose, ""), "POSE");
  EXPECT_EQ(channels::prefixedName("ESTIMATOR_STATUS", "ifo-001_a"), "ifo-001_a/ESTIMATOR_STATUS");
  // Exactly three channels are shared; every other one of the table is a vehicle's.
  int shared = 0;
  for (const char* n : channels::kAll) {
    const std::string wire = channels::prefixedName(n, "v1");
    if (channels::isFleetShared(n)) {
      ++shared;
      EXPECT_EQ(wire, n);
    } else {
      EXPECT_EQ(wire, std::string("v1/") + n);
    }
    EXPECT_EQ(channels::unprefixedName(wire), n);
  }
  EXPECT_EQ(shared, 3);
}

TEST(ChannelPrefix, MalformedPrefixesAreRefusedWithTheReason) {
  EXPECT_EQ(channels::prefixProblem("UAV1"), "");
  EXPECT_EQ(channels::prefixProblem(std::string(64, 'a')), "");
  for (const std::string& bad : std::vector<std::string>{"", "a/b", "v 0", "v0.", "ä", std::string(65, 'a'), "POSE|IMU"}) {
    EXPECT_NE(channels::prefixProblem(bad), "") << bad;
    EXPECT_THROW(channels::prefixedName("POSE", bad.empty() ? "/" : bad), std::invalid_argument) << bad;
  }
  EXPECT_EQ(channels::prefixProblem("a/b"), "'a/b' must be 1-64 letters, digits, '_' or '-' (a vehicle name of the fleet file)");
  EXPECT_THROW(LcmNode("test", "memq://", "a/b"), std::invalid_argument);
}

// Two vehicles' nodes on one bus: each hears its own POSE only, never the other's; a shared
// channel reaches both; waitForMessage waits for the node's own vehicle's channel.
TEST(ChannelPrefix, NodesOfTwoVehiclesDoNotHearEachOther) {
  LcmNode v0("v0", "memq://", "v0");
  LcmNode v1("v1", "memq://", "v1");
  // memq:// is one bus per LCM instance: publish and receive within each node, and check what
  // went on the wire by name with a raw subscription.
  std::vector<std::string> wire;
  v0.subscribeRaw(".*", [&](const lcm::ReceiveBuffer&, const std::string& ch) { wire.push_back(ch); });
  int poses = 0, calib = 0;
  v0.subscribe(channels::kPose, [&](const PoseEstimate&) { ++poses; });
  v0.subscribe(channels::kCalibStatus, [&](const CalibStatus&) { ++calib; });
  PoseEstimate p;
  p.t = Timestamp{1000};
  ASSERT_TRUE(v0.publish(channels::kPose, p));
  ASSERT_TRUE(v0.publish(channels::kCalibStatus, CalibStatus{}));
  // What v1 would publish, by its wire name: a raw POSE on "v1/POSE" is not v0's POSE.
  pose_t other = toLcm(p);
  v0.lcm().publish("v1/POSE", &other);
  v0.lcm().publish("POSE", &other);
  while (v0.spinOnce(0) > 0) {
  }
  EXPECT_EQ(poses, 1);
  EXPECT_EQ(calib, 1);
  EXPECT_EQ(wire, (std::vector<std::string>{"v0/POSE", "CALIB_STATUS", "v1/POSE", "POSE"}));
  EXPECT_EQ(v0.received("v0/POSE"), 1);
  EXPECT_EQ(v1.wireName(channels::kImu), "v1/IMU");
}

}  // namespace
}  // namespace meshnav::transport
