/// EstimatorNode and its time guard (issue 12, finding 1): one input stamped +1 h used to make every
/// later input "rejected_too_old" for good. Far-stamped inputs are now refused, counted per kind,
/// and leave the estimate exactly as without them; a jump of the whole stream is followed.
#include <gtest/gtest.h>

#include <random>

#include "node_test_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

synthetic::SyntheticOptions scenario() { return test::shortNoisyFlight(5); }

/// Runs `inputs` through a node, calling `inject(node, t_s)` before every input.
template <class Inject>
std::unique_ptr<EstimatorNode> run(const Dataset& ds, const std::vector<EstimatorInput>& inputs, Inject inject) {
  auto node = std::make_unique<EstimatorNode>(test::testOptions(), ds.setup);
  for (const auto& in : inputs) {
    inject(*node, inputTime(in).sec());
    node->onInput(in);
  }
  return node;
}

int64_t counter(const EstimatorNode& n, const std::string& key) { return n.diagnostics().get(key); }

}  // namespace

TEST(EstimatorTimeGuard, FutureStampedInputsAreRefusedAndChangeNothing) {
  const Dataset ds = synthetic::makeSyntheticDataset(scenario());
  const auto inputs = mergeInTimeOrder(ds);
  const auto clean = run(ds, inputs, [](EstimatorNode&, double) {});
  ASSERT_TRUE(clean->initialized());

  bool injected = false;
  const auto node = run(ds, inputs, [&](EstimatorNode& n, double t) {
    if (injected || t < 6.0) return;
    injected = true;
    const Timestamp future = Timestamp::fromSec(t + 3600.0);
    RangeSample r = ds.ranges.front();
    r.t = future;
    n.onRange(r);
    ImuSample s = ds.imu.front();
    s.t = future;
    n.onImu(s);
    n.onBaro({future, 101325.0});
    n.onFlightState({future, true});
  });
  ASSERT_TRUE(injected);
  EXPECT_EQ(counter(*node, "RANGE:time_ahead"), 1);
  EXPECT_EQ(counter(*node, "IMU:time_ahead"), 1);
  EXPECT_EQ(counter(*node, "BARO:time_ahead"), 1);
  EXPECT_EQ(counter(*node, "FLIGHT_STATE:time_ahead"), 1);
  EXPECT_EQ(counter(*node, "rejected_too_old"), 0);
  // The clock never moved: the estimate is exactly the one without the bad inputs.
  EXPECT_EQ(node->status().t, clean->status().t);
  EXPECT_EQ(test::stateDifference(*clean->filter(), *node->filter()), 0.0);
}

TEST(EstimatorTimeGuard, ABurstFromOneSourceNeverMovesTheClock) {
  // Issue 36: 100 IMU messages stamped +1 h in a row (more than time.rebase_after) were taken as the
  // whole stream moving: the estimator propagated across the hour and published poses 500 km
  // away. The other sources never agreed: the burst is refused as the IMU's fault, reported once,
  // and the estimate is exactly the one without it.
  const Dataset ds = synthetic::makeSyntheticDataset(scenario());
  const auto inputs = mergeInTimeOrder(ds);
  const auto clean = run(ds, inputs, [](EstimatorNode&, double) {});
  const int burst = 2 * test::testOptions().time.rebase_after;
  ASSERT_GE(burst, 100);
  bool injected = false;
  const auto node = run(ds, inputs, [&](EstimatorNode& n, double t) {
    if (injected || t < 6.0) return;
    injected = true;
    for (int i = 0; i < burst; ++i) {
      ImuSample s = ds.imu.front();
      s.t = Timestamp::fromSec(t + 3600.0 + 0.005 * i);
      n.onImu(s);
    }
  });
  ASSERT_TRUE(injected);
  EXPECT_EQ(counter(*node, "IMU:time_ahead"), burst);
  EXPECT_EQ(counter(*node, "IMU:time_jump_alone"), 1);
  EXPECT_EQ(counter(*node, "time_rebased"), 0);
  EXPECT_EQ(node->status().t, clean->status().t);
  EXPECT_EQ(test::stateDifference(*clean->filter(), *node->filter()), 0.0);
}

TEST(EstimatorTimeGuard, RandomImuBytesDoNotMoveTheEstimate) {
  // What random bytes behind a valid imu_t fingerprint decode to: any utime, readings that may
  // even look plausible. Sprinkled over the flight they must leave the estimate as it was.
  const Dataset ds = synthetic::makeSyntheticDataset(scenario());
  const auto inputs = mergeInTimeOrder(ds);
  const auto clean = run(ds, inputs, [](EstimatorNode&, double) {});
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> reading(-9.0, 9.0);
  int sent = 0;
  const auto node = run(ds, inputs, [&](EstimatorNode& n, double) {
    if (rng() % 20 != 0) return;
    ImuSample s;
    s.t = Timestamp{static_cast<int64_t>(rng())};
    s.acc_m_s2 = {reading(rng), reading(rng), reading(rng)};
    s.gyro_rad_s = {reading(rng), reading(rng), reading(rng)};
    n.onImu(s);
    ++sent;
  });
  ASSERT_GT(sent, 100);
  EXPECT_EQ(counter(*node, "IMU:time_ahead") + counter(*node, "IMU:time_behind"), sent);
  ASSERT_TRUE(node->initialized());
  EXPECT_EQ(test::stateDifference(*clean->filter(), *node->filter()), 0.0);
  EXPECT_LT(node->pose()->p_IinG.norm(), 100.0);
}

TEST(EstimatorTimeGuard, AWrongFirstInputIsLeftBehind) {
  // The very first input is stamped +1 h (nothing to compare it with): the node trusts it, then
  // `time.rebase_after` agreeing inputs take the clock back and the node starts over: from then on
  // it is a node that never saw the inputs before the last of those.
  const Dataset ds = synthetic::makeSyntheticDataset(scenario());
  const auto inputs = mergeInTimeOrder(ds);
  const int n_refused = test::testOptions().time.rebase_after - 1;
  const std::vector<EstimatorInput> rest(inputs.begin() + n_refused, inputs.end());
  const auto fresh = run(ds, rest, [](EstimatorNode&, double) {});
  bool injected = false;
  const auto node = run(ds, inputs, [&](EstimatorNode& n, double t) {
    if (injected) return;
    injected = true;
    ImuSample s = ds.imu.front();
    s.t = Timestamp::fromSec(t + 3600.0);
    n.onImu(s);
  });
  EXPECT_EQ(counter(*node, "time_rebased"), 1);
  ASSERT_TRUE(node->initialized());
  EXPECT_EQ(node->status().t, inputTime(inputs.back()));
  EXPECT_EQ(counter(*node, "IMU:time_behind") + counter(*node, "RANGE:time_behind") +
                counter(*node, "BARO:time_behind") + counter(*node, "FLIGHT_STATE:time_behind"),
            n_refused);
  EXPECT_EQ(counter(*node, "rejected_too_old"), 0);
  ASSERT_TRUE(fresh->initialized());
  EXPECT_EQ(test::stateDifference(*fresh->filter(), *node->filter()), 0.0);
}

TEST(EstimatorTimeGuard, AJumpOfTheWholeStreamIsFollowed) {
  // A recording that pauses: every input after 6 s is stamped 60 s later.
  const Dataset ds = synthetic::makeSyntheticDataset(scenario());
  auto inputs = mergeInTimeOrder(ds);
  for (auto& in : inputs)
    std::visit([](auto& m) { if (m.t.sec() > 6.0) m.t = m.t + Duration::fromSec(60.0); }, in);
  const auto node = run(ds, inputs, [](EstimatorNode&, double) {});
  const EstimatorOptions o = test::testOptions();
  EXPECT_EQ(counter(*node, "time_rebased"), 1);
  int64_t refused = 0;
  for (const auto& [k, v] : node->diagnostics().snapshot())
    if (k.find(":time_ahead") != std::string::npos) refused += v;
  EXPECT_EQ(refused, o.time.rebase_after - 1);
  EXPECT_EQ(node->status().t, inputTime(inputs.back()));
  EXPECT_TRUE(node->pose()->p_IinG.allFinite());
}

TEST(EstimatorTimeGuard, FarStampedCommandsApplyNow) {
  const Dataset ds = synthetic::makeSyntheticDataset(scenario());
  const auto inputs = mergeInTimeOrder(ds);
  bool injected = false;
  const auto node = run(ds, inputs, [&](EstimatorNode& n, double t) {
    if (injected || t < 6.0) return;
    injected = true;
    AnchorInit a;
    a.id = 120;
    a.t = Timestamp::fromSec(t + 3600.0);
    a.p_AinG = {1.0, 2.0, 3.0};
    a.cov_p_m2 = 0.01 * Eigen::Matrix3d::Identity();
    n.onAnchorInit(a);
  });
  EXPECT_EQ(counter(*node, "ANCHOR_INIT:time_clamped"), 1);
  EXPECT_EQ(counter(*node, "anchor_init"), 1);
  EXPECT_EQ(counter(*node, "rejected_too_old"), 0);
  EXPECT_EQ(node->status().t, inputTime(inputs.back()));
}

TEST(EstimatorTimeGuard, ACommandStampedAheadBeforeAnyMeasurementDoesNotMoveTheClock) {
  // Found by an audit: before the first measurement the node took the command's stamp (+1 h) as
  // its newest time, and every later measurement was "rejected_too_old" for good.
  const Dataset ds = synthetic::makeSyntheticDataset(scenario());
  const auto inputs = mergeInTimeOrder(ds);
  const auto clean = run(ds, inputs, [](EstimatorNode&, double) {});
  ASSERT_TRUE(clean->initialized());
  bool injected = false;
  const auto node = run(ds, inputs, [&](EstimatorNode& n, double t) {
    if (injected) return;
    injected = true;
    AnchorInit a;
    a.id = 120;
    a.t = Timestamp::fromSec(t + 3600.0);
    a.p_AinG = {1.0, 2.0, 3.0};
    a.cov_p_m2 = 0.01 * Eigen::Matrix3d::Identity();
    n.onAnchorInit(a);
    EstimatorCommand c;
    c.t = Timestamp::fromSec(t + 7200.0);
    c.action = EstimatorCommand::Action::RemoveInstance;
    c.id = 121;
    n.onCommand(c);
  });
  ASSERT_TRUE(node->initialized());
  EXPECT_EQ(counter(*node, "rejected_too_old"), 0);
  EXPECT_EQ(node->status().t, inputTime(inputs.back()));
  EXPECT_TRUE(node->filter()->layout().find(120) != nullptr);  // applied at initialization
}
