/// Out-of-sequence handling: delayed inputs give exactly the in-order result; inputs older than the
/// window are rejected and counted without touching the estimate.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <random>

#include "node_test_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

synthetic::SyntheticOptions scenario() {
  synthetic::SyntheticOptions o;
  o.duration_s = 12.0;
  o.landed_s = 3.0;
  o.noise = true;
  o.n_estimated_anchors = 2;
  o.seed = 7;
  return o;
}

/// A node with `options` that has processed `inputs` in their order.
std::unique_ptr<EstimatorNode> processedInOrder(const Dataset& ds, const EstimatorOptions& options,
                                                const std::vector<EstimatorInput>& inputs) {
  auto node = std::make_unique<EstimatorNode>(options, ds.setup);
  for (const auto& in : inputs) node->onInput(in);
  return node;
}

/// The same state (≤ 1e-9) and the same per-instance counts of first processing (the same
/// measurements fused and gated); returns the number fused.
int64_t expectSameEstimateAndCounts(const EstimatorNode& expected, const EstimatorNode& actual) {
  EXPECT_LE(test::stateDifference(*expected.filter(), *actual.filter()), 1e-9);
  const auto a = expected.status().instances, b = actual.status().instances;
  EXPECT_EQ(a.size(), b.size());
  int64_t fused = 0;
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    EXPECT_EQ(a[i].id, b[i].id);
    EXPECT_EQ(a[i].n_updates, b[i].n_updates) << "instance " << a[i].id;
    EXPECT_EQ(a[i].n_rejected, b[i].n_rejected) << "instance " << a[i].id;
    fused += a[i].n_updates;
  }
  return fused;
}

}  // namespace

/// Delayed arrival against in-order processing; `hold`: measurements wait for the IMU sample after
/// them (imu.hold_for_next_sample), which a rewind finds again in the stored inputs.
void expectDelayedInputsEqualInOrderProcessing(bool hold) {
  const Dataset ds = synthetic::makeSyntheticDataset(scenario());
  const auto inputs = mergeInTimeOrder(ds);
  EstimatorOptions options = test::testOptions();
  options.imu.hold_for_next_sample = hold;
  const auto in_order = processedInOrder(ds, options, inputs);
  ASSERT_TRUE(in_order->initialized());

  // Arrival = time + a random delay of up to 0.4 s for ranges and baro (other processes),
  // IMU and flight state on time: many inputs arrive after newer ones. The first 2 s (the static
  // initialization takes the first second) arrive in order: initialization uses what has arrived.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> delay(0.0, 0.4);
  std::vector<std::pair<double, EstimatorInput>> arrivals;
  for (const auto& in : inputs) {
    double d = 0.0;
    const bool other_process = std::holds_alternative<RangeSample>(in) || std::holds_alternative<BaroSample>(in);
    if (other_process && inputTime(in).sec() > 2.0) d = delay(rng);
    arrivals.emplace_back(inputTime(in).sec() + d, in);
  }
  std::stable_sort(arrivals.begin(), arrivals.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  EstimatorNode delayed(options, ds.setup);
  for (const auto& [t, in] : arrivals) delayed.onInput(in);

  ASSERT_TRUE(delayed.initialized());
  EXPECT_GT(delayed.diagnostics().get("out_of_sequence"), 100);
  EXPECT_EQ(delayed.diagnostics().get("rejected_too_old"), 0);
  // Both fused (and gated) the same measurements: per-instance counts of first processing agree.
  EXPECT_GT(expectSameEstimateAndCounts(*in_order, delayed), 100);
}

TEST(OutOfSequence, DelayedInputsEqualInOrderProcessing) { expectDelayedInputsEqualInOrderProcessing(false); }

TEST(OutOfSequence, MeasurementsHeldForTheNextImuSampleAreProcessedInOrderWhateverTheirArrival) {
  // Between two IMU samples the measurements arrive in reverse order, and a flight state stamped
  // after them arrives before the sample: the node holds them, then processes them in the
  // canonical order, each interpolated towards the same sample, as in-order arrival does.
  const Dataset ds = synthetic::makeSyntheticDataset(scenario());
  const auto inputs = mergeInTimeOrder(ds);
  EstimatorOptions options = test::testOptions();
  options.imu.hold_for_next_sample = true;
  const auto in_order = processedInOrder(ds, options, inputs);
  ASSERT_TRUE(in_order->initialized());

  std::vector<EstimatorInput> arrivals;
  std::vector<EstimatorInput> between;  // the inputs after the last IMU sample, reversed at the next
  int reversed = 0, flight_states_between = 0;
  for (const auto& in : inputs) {
    if (!std::holds_alternative<ImuSample>(in)) {
      between.push_back(in);
      continue;
    }
    if (between.size() >= 2 && isMeasurement(between.front()) && isMeasurement(between.back())) ++reversed;
    for (auto it = between.rbegin(); it != between.rend(); ++it) arrivals.push_back(*it);
    if (!between.empty() && inputTime(arrivals.back()).sec() > 3.5) {
      // A flight state stamped just before the sample, arriving before the held measurements' release.
      arrivals.push_back(FlightStateSample{inputTime(in) - Duration::fromMs(0.001), false});
      ++flight_states_between;
    }
    between.clear();
    arrivals.push_back(in);
  }
  for (const auto& in : between) arrivals.push_back(in);
  ASSERT_GT(reversed, 50);
  ASSERT_GT(flight_states_between, 100);
  const auto delayed = processedInOrder(ds, options, arrivals);
  ASSERT_TRUE(delayed->initialized());
  // Flight states are not measurements: they join the in-order run's result only through `landed`,
  // which the added ones (airborne, after 3.5 s, as the flight is) leave as it is.
  expectSameEstimateAndCounts(*in_order, *delayed);
}

TEST(OutOfSequence, DelayedInputsEqualInOrderProcessingWithMeasurementsHeldForTheNextImuSample) {
  expectDelayedInputsEqualInOrderProcessing(true);
}

TEST(OutOfSequence, TooOldInputIsRejectedAndCounted) {
  const Dataset ds = synthetic::makeSyntheticDataset(scenario());
  const auto inputs = mergeInTimeOrder(ds);
  EstimatorNode node(test::testOptions(), ds.setup);
  EstimatorNode reference(test::testOptions(), ds.setup);
  for (const auto& in : inputs) {
    node.onInput(in);
    reference.onInput(in);
  }
  ASSERT_TRUE(node.initialized());
  const Timestamp newest = node.filter()->state().t;
  RangeSample old = ds.ranges.back();
  old.t = newest - Duration::fromSec(1.5);  // beyond the 1 s window
  node.onRange(old);
  ImuSample old_imu = ds.imu.back();
  old_imu.t = newest - Duration::fromSec(3.0);  // time going backwards beyond the window
  node.onImu(old_imu);
  EXPECT_EQ(node.diagnostics().get("rejected_too_old"), 2);
  EXPECT_EQ(test::stateDifference(*node.filter(), *reference.filter()), 0.0);
}

TEST(OutOfSequence, HistoryIsBoundedByTheWindow) {
  const Dataset ds = synthetic::makeSyntheticDataset(scenario());
  EstimatorOptions o = test::testOptions();
  o.window_s = 0.5;
  EstimatorNode node(o, ds.setup);
  for (const auto& in : mergeInTimeOrder(ds)) node.onInput(in);
  // 0.5 s of 200 Hz IMU, 20 Hz baro and the ranges: a few hundred entries, not the whole run.
  EXPECT_GT(node.historySize(), 100u);
  EXPECT_LT(node.historySize(), 600u);
}
