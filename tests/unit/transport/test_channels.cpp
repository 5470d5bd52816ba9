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
  EXPECT_GE(n, 7);
}

TEST(Channels, NamesAreDistinctAndUpperSnake) {
  std::set<std::string> names;
  for (const char* n : channels::kAll) {
    const std::string s(n);
    EXPECT_TRUE(names.insert(s).second) << s << " twice";
    for (char c : s) EXPECT_TRUE((c >= 'A' && c <= 'Z') || c == '_') << s;
  }
  EXPECT_EQ(names.size(), 19u);
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

}  // namespace
}  // namespace meshnav::transport
