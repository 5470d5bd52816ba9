/// Issue 12, finding 1, through the whole LCM path of the estimator process (decode, conversion,
/// EstimatorNode, wired as estimator/process/main.cpp does, on memq://): a RANGE stamped +1 h and
/// random bytes behind a correct imu_t fingerprint are refused and counted, and the estimate is
/// bit-identical to the run without them (it used to stop for good, or reach about 1e25 m).
#include <gtest/gtest.h>

#include <random>

#include "tests/unit/estimator/node_test_helpers.h"
#include "transport/channels.h"
#include "transport/lcm_node.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

synthetic::SyntheticOptions scenario() { return test::shortNoisyFlight(9); }

/// Publishes every input of `ds` over memq into an EstimatorNode; `inject(lcm, t_s)` before each.
template <class Inject>
std::unique_ptr<EstimatorNode> runOverLcm(const Dataset& ds, transport::LcmNode& lcm, Inject inject) {
  auto node = std::make_unique<EstimatorNode>(EstimatorOptions{}, ds.setup);
  lcm.subscribe(channels::kImu, [&n = *node](const ImuSample& s) { n.onImu(s); });
  lcm.subscribe(channels::kBaro, [&n = *node](const BaroSample& s) { n.onBaro(s); });
  lcm.subscribe(channels::kRange, [&n = *node](const RangeSample& s) { n.onRange(s); });
  lcm.subscribe(channels::kFlightState,
                                   [&n = *node](const FlightStateSample& s) { n.onFlightState(s); });
  auto drain = [&] {
    while (lcm.spinOnce(0) > 0) {
    }
  };
  for (const auto& in : mergeInTimeOrder(ds)) {
    inject(lcm, inputTime(in).sec());
    std::visit(
        [&](const auto& m) {
          using T = std::decay_t<decltype(m)>;
          if constexpr (std::is_same_v<T, ImuSample>) lcm.publish(channels::kImu, m);
          if constexpr (std::is_same_v<T, BaroSample>) lcm.publish(channels::kBaro, m);
          if constexpr (std::is_same_v<T, RangeSample>) lcm.publish(channels::kRange, m);
          if constexpr (std::is_same_v<T, FlightStateSample>) lcm.publish(channels::kFlightState, m);
        },
        in);
    drain();
  }
  return node;
}

}  // namespace

TEST(LcmBadTime, FutureRangeAndRandomImuBytesChangeNothing) {
  const Dataset ds = synthetic::makeSyntheticDataset(scenario());
  transport::LcmNode clean_lcm("clean", "memq://");
  const auto clean = runOverLcm(ds, clean_lcm, [](transport::LcmNode&, double) {});
  ASSERT_TRUE(clean->initialized());

  transport::LcmNode lcm("bad", "memq://");
  std::mt19937_64 rng(5);
  const auto valid = transport::toLcm(ImuSample{});
  std::vector<uint8_t> bytes(static_cast<size_t>(valid.getEncodedSize()));
  valid.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  bool future_sent = false;
  int random_sent = 0;
  const auto node = runOverLcm(ds, lcm, [&](transport::LcmNode& l, double t) {
    if (!future_sent && t > 5.0) {
      RangeSample r = ds.ranges.front();
      r.t = Timestamp::fromSec(t + 3600.0);
      l.publish(channels::kRange, r);
      future_sent = true;
    }
    if (rng() % 20 == 0) {
      for (size_t i = 8; i < bytes.size(); ++i) bytes[i] = static_cast<uint8_t>(rng());  // keep the fingerprint
      l.lcm().publish(channels::kImu.name, bytes.data(), static_cast<unsigned>(bytes.size()));
      ++random_sent;
    }
  });
  ASSERT_TRUE(future_sent);
  ASSERT_GT(random_sent, 100);
  const Diagnostics& nd = node->diagnostics();
  EXPECT_EQ(nd.get("RANGE:time_ahead"), 1);
  EXPECT_EQ(nd.get("rejected_too_old"), 0);
  // Every random message is refused somewhere on the way, and counted there.
  const int64_t refused = lcm.diagnostics().get("IMU:decode_error") + lcm.diagnostics().get("IMU:invalid_message") +
                          nd.get("IMU:time_ahead") + nd.get("IMU:time_behind") + nd.get("bad_input");
  EXPECT_EQ(refused, random_sent);
  ASSERT_TRUE(node->initialized());
  EXPECT_EQ(node->status().t, clean->status().t);
  const auto p = node->pose(), q = clean->pose();
  EXPECT_EQ(p->p_IinG, q->p_IinG);
  EXPECT_EQ(p->q_ItoG.coeffs(), q->q_ItoG.coeffs());
  EXPECT_EQ(p->cov_p_m2, q->cov_p_m2);
  EXPECT_LT(p->p_IinG.norm(), 100.0);
}
