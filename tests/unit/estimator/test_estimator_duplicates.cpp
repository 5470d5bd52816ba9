/// EstimatorNode and duplicated inputs (issue 12, item 3: tc netem duplicates datagrams, a sender
/// may retransmit): an input that comes a second time is dropped and counted per kind, so a range is
/// never fused twice and the estimate equals the one without duplicates.
#include <gtest/gtest.h>

#include <random>

#include "node_test_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

int64_t counter(const EstimatorNode& n, const std::string& key) { return n.diagnostics().get(key); }

}  // namespace

TEST(EstimatorDuplicates, DuplicatedInputsAreDroppedCountedAndChangeNothing) {
  const Dataset ds = synthetic::makeSyntheticDataset(test::shortNoisyFlight(5));
  const auto inputs = mergeInTimeOrder(ds);
  EstimatorNode clean(test::testOptions(), ds.setup);
  for (const auto& in : inputs) clean.onInput(in);
  ASSERT_TRUE(clean.initialized());

  // 10 % of the inputs come twice: at once, or again up to 40 inputs later (a delayed copy, within
  // the out-of-sequence window), before and after initialization.
  std::mt19937 rng(3);
  std::map<std::string, int64_t> sent_twice;
  std::vector<std::pair<size_t, EstimatorInput>> later;  // (deliver before input i, copy)
  EstimatorNode node(test::testOptions(), ds.setup);
  for (size_t i = 0; i < inputs.size(); ++i) {
    for (auto it = later.begin(); it != later.end();) {
      if (it->first == i) {
        node.onInput(it->second);
        it = later.erase(it);
      } else {
        ++it;
      }
    }
    node.onInput(inputs[i]);
    if (rng() % 10 != 0) continue;
    ++sent_twice[inputKindName(inputs[i])];
    if (rng() % 2)
      node.onInput(inputs[i]);
    else
      later.emplace_back(i + 1 + rng() % 40, inputs[i]);
  }
  for (const auto& [i, in] : later) node.onInput(in);
  ASSERT_GT(sent_twice["RANGE"], 10);
  ASSERT_GT(sent_twice["IMU"], 100);
  for (const auto& [kind, n] : sent_twice) EXPECT_EQ(counter(node, kind + ":duplicate"), n) << kind;
  EXPECT_EQ(counter(node, "rejected_too_old"), 0);
  // Every range was fused once: the same updates as the clean run, the same estimate.
  EXPECT_EQ(node.status().t, clean.status().t);
  EXPECT_EQ(test::stateDifference(*clean.filter(), *node.filter()), 0.0);
}

TEST(EstimatorDuplicates, DistinctRangesAtTheSameTimeAreNotDuplicates) {
  // Two tags ranging at the same instant, or the same pair in both directions: different keys.
  const Dataset ds = synthetic::makeSyntheticDataset(test::shortNoisyFlight(5));
  EstimatorNode node(test::testOptions(), ds.setup);
  RangeSample a = ds.ranges.front();
  RangeSample b = a;
  std::swap(b.id_initiator, b.id_responder);
  std::swap(b.type_initiator, b.type_responder);
  node.onRange(a);
  node.onRange(b);
  EXPECT_EQ(counter(node, "RANGE:duplicate"), 0);
  node.onRange(b);
  EXPECT_EQ(counter(node, "RANGE:duplicate"), 1);
}
