// The re-run on an anchor join off the publishing path (refine.rerun_mode async, issue 10): while
// the worker computes it (held by a test hook until released), the node keeps processing and
// publishing poses; after the swap the state equals the inline (sync) re-run's on the same inputs
// bit for bit, also when late inputs were inserted among the re-run's own meanwhile and when a
// second anchor joined meanwhile (queued: one more re-run with both anchors after the swap).
#include <gtest/gtest.h>

#include <condition_variable>
#include <mutex>

#include "estimator/testing/estimator_node_testing.h"
#include "estimator/node/estimator_node.h"
#include "estimator/testing/synthetic_scenario.h"
#include "node_test_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

/// A calibration 0.2 m off whose covariance says so.
AnchorInit calibration(SensorId id, Timestamp t) {
  AnchorInit a;
  a.t = t;
  a.id = id;
  a.p_AinG = synthetic::syntheticAnchors(2).at(id) + Eigen::Vector3d(0.12, -0.12, 0.10);
  a.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.12 * 0.12;
  return a;
}

EstimatorOptions options(const std::string& mode) {
  EstimatorOptions o = test::testOptions();
  o.strategy = "dp";
  o.refine.rerun_mode = mode;
  return o;
}

/// Holds the re-run worker until released (conditions, no sleeps).
class Gate {
 public:
  void hold() {
    std::unique_lock<std::mutex> l(m_);
    ++entered_;
    cv_.notify_all();
    cv_.wait(l, [&] { return open_; });
  }
  void waitEntered(int n) {
    std::unique_lock<std::mutex> l(m_);
    cv_.wait(l, [&] { return entered_ >= n; });
  }
  void release() {
    std::lock_guard<std::mutex> l(m_);
    open_ = true;
    cv_.notify_all();
  }

 private:
  std::mutex m_;
  std::condition_variable cv_;
  int entered_ = 0;
  bool open_ = false;
};

/// An inline (sync) node and a held async node fed the same inputs in lockstep.
struct Pair {
  explicit Pair(const Dataset& ds)
      : sync(options("sync"), ds.setup),
        async(options("async"), ds.setup, EstimatorSinks{[this](const PoseEstimate&) { ++async_poses; }, {}, {}}) {
    EstimatorNodeTesting::setRerunWorkerHook(async, [this] { gate.hold(); });
  }
  void feed(const EstimatorInput& in) {
    sync.onInput(in);
    async.onInput(in);
  }
  /// Feeds inputs[i..] before `t_s`, the join of `id` stamped at the newest input (every later
  /// input sorts after it) and the next input, which starts the re-run; waits until the worker
  /// is held. Returns the index of the next input.
  size_t joinAt(const std::vector<EstimatorInput>& inputs, size_t i, double t_s, SensorId id) {
    for (; inputTime(inputs[i]).sec() < t_s; ++i) feed(inputs[i]);
    feed(calibration(id, inputTime(inputs[i - 1])));
    feed(inputs[i++]);
    gate.waitEntered(1);
    return i;
  }
  EstimatorNode sync;
  int64_t async_poses = 0;
  Gate gate;
  EstimatorNode async;
};

bool isImu(const EstimatorInput& in) { return std::holds_alternative<ImuSample>(in); }

}  // namespace

TEST(AnchorRerunAsync, PublishesWhileTheReRunIsHeldAndSwapsInTheInlineResult) {
  const Dataset ds = test::flightWithUnknownAnchors(2);
  const auto inputs = mergeInTimeOrder(ds);
  Pair p(ds);
  size_t i = p.joinAt(inputs, 0, 20.0, 106);
  ASSERT_TRUE(p.async.rerunRunning());
  EXPECT_FALSE(p.sync.rerunRunning());
  // 2 s of data while the worker is held: a pose for every IMU step, from the live filter.
  const int64_t poses_before = p.async_poses;
  int64_t imu_steps = 0;
  for (; inputTime(inputs[i]).sec() < 22.0; ++i) {
    p.feed(inputs[i]);
    imu_steps += isImu(inputs[i]);
  }
  EXPECT_TRUE(p.async.rerunRunning());
  EXPECT_EQ(p.async.diagnostics().get("out_of_sequence"), 0);
  EXPECT_EQ(p.async_poses - poses_before, imu_steps);
  EXPECT_GT(imu_steps, 300);
  EXPECT_GT(test::stateDifference(*p.sync.filter(), *p.async.filter()), 1e-6);  // not the re-run's state yet
  p.gate.release();
  p.async.finishRerun();
  EXPECT_FALSE(p.async.rerunRunning());
  // The swap re-processed the inputs of the 2 s from the re-run's state: the inline result.
  EXPECT_EQ(test::stateDifference(*p.sync.filter(), *p.async.filter()), 0.0);
  EXPECT_GE(p.async.diagnostics().get("rerun_replayed"), static_cast<int64_t>(imu_steps));
  for (; i < inputs.size(); ++i) p.feed(inputs[i]);
  EXPECT_EQ(test::stateDifference(*p.sync.filter(), *p.async.filter()), 0.0);
  EXPECT_EQ(p.sync.diagnostics().get("rerun"), 1);
  EXPECT_EQ(p.async.diagnostics().get("rerun"), 1);
  EXPECT_EQ(p.async.diagnostics().get("rerun_inputs"), p.sync.diagnostics().get("rerun_inputs"));
}

TEST(AnchorRerunAsync, LateInputsInsertedAmongTheReRunsOwnAreReProcessedAtTheSwap) {
  const Dataset ds = test::flightWithUnknownAnchors(2);
  const auto inputs = mergeInTimeOrder(ds);
  Pair p(ds);
  // Ranges of the 0.5 s before the join held back and delivered while the worker is held: they land
  // among the re-run's own inputs (inside the 1 s window), so its snapshots hold only before them.
  std::vector<EstimatorInput> held;
  size_t i = 0;
  for (; inputTime(inputs[i]).sec() < 20.0; ++i) {
    if (inputTime(inputs[i]).sec() >= 19.5 && std::holds_alternative<RangeSample>(inputs[i]))
      held.push_back(inputs[i]);
    else
      p.feed(inputs[i]);
  }
  ASSERT_FALSE(held.empty());
  p.feed(calibration(106, inputTime(inputs[i])));
  p.feed(inputs[i++]);
  p.gate.waitEntered(1);
  for (; inputTime(inputs[i]).sec() < 20.3; ++i) p.feed(inputs[i]);
  for (const auto& h : held) p.feed(h);
  for (; inputTime(inputs[i]).sec() < 21.0; ++i) p.feed(inputs[i]);
  EXPECT_GT(p.async.diagnostics().get("out_of_sequence"), 0);
  p.gate.release();
  p.async.finishRerun();
  EXPECT_EQ(test::stateDifference(*p.sync.filter(), *p.async.filter()), 0.0);
  for (; i < inputs.size(); ++i) p.feed(inputs[i]);
  EXPECT_EQ(test::stateDifference(*p.sync.filter(), *p.async.filter()), 0.0);
  EXPECT_EQ(p.async.diagnostics().get("rerun_swap_failed"), 0);
}

TEST(AnchorRerunAsync, ASecondJoinWhileRunningIsQueuedAndReRunsWithBothAnchors) {
  const Dataset ds = test::flightWithUnknownAnchors(2);
  const auto inputs = mergeInTimeOrder(ds);
  Pair p(ds);
  size_t i = p.joinAt(inputs, 0, 18.0, 106);
  for (; inputTime(inputs[i]).sec() < 20.0; ++i) p.feed(inputs[i]);
  p.feed(calibration(107, inputTime(inputs[i])));
  for (; inputTime(inputs[i]).sec() < 22.0; ++i) p.feed(inputs[i]);
  // Inline: two re-runs by now; async: the first still held, the second queued behind it.
  EXPECT_EQ(p.sync.diagnostics().get("rerun"), 2);
  EXPECT_EQ(p.async.diagnostics().get("rerun"), 1);
  EXPECT_EQ(p.async.diagnostics().get("rerun_queued"), 1);
  EXPECT_TRUE(p.async.rerunRunning());
  p.gate.release();
  p.async.finishRerun();  // swaps the first in, runs the queued one and swaps it in
  EXPECT_FALSE(p.async.rerunRunning());
  EXPECT_EQ(p.async.diagnostics().get("rerun"), 2);
  // The second re-run restored the same oldest state with both anchors uncertain and re-processed
  // the same inputs (later than the inline one, which makes no difference): the inline result.
  EXPECT_EQ(test::stateDifference(*p.sync.filter(), *p.async.filter()), 0.0);
  for (; i < inputs.size(); ++i) p.feed(inputs[i]);
  EXPECT_EQ(test::stateDifference(*p.sync.filter(), *p.async.filter()), 0.0);
  for (SensorId id : {106, 107})
    EXPECT_LT((p.async.filter()->state().values<AnchorKind>().at(id).p_AinG - synthetic::syntheticAnchors(2).at(id))
                  .norm(),
              0.1)
        << id;
}

TEST(AnchorRerunAsync, AReInitializationAbandonsARunningReRun) {
  const Dataset ds = test::flightWithUnknownAnchors(2);
  const auto inputs = mergeInTimeOrder(ds);
  Pair p(ds);
  size_t i = p.joinAt(inputs, 0, 20.0, 106);
  p.gate.release();  // the worker may finish or not: the fault drops it either way
  EstimatorNodeTesting::injectPoseError(p.async, Eigen::Vector3d(1.0, 0.0, 0.0), 0.0);  // replaces the IMU instance: no re-run base left
  EXPECT_FALSE(p.async.rerunRunning());
  EXPECT_EQ(p.async.diagnostics().get("rerun_abandoned"), 1);
  for (; i < inputs.size(); ++i) p.async.onInput(inputs[i]);
  EXPECT_FALSE(p.async.rerunRunning());
  EXPECT_EQ(p.async.diagnostics().get("rerun"), 1);
}
