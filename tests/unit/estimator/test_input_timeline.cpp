/// InputTimeline (estimator/node/input_timeline.h): the window sorted by input order, the start and
/// window bounds, inputs leaving the window archived with a checkpoint every eighth of
/// refine.max_history_s (and the oldest), the archive cut at a checkpoint and counted, restart.
#include <gtest/gtest.h>

#include "estimator/node/input_timeline.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

Timestamp at(double s) { return Timestamp::fromSec(s); }

/// A baro sample at `s` (any kind will do: the timeline only orders and stores).
EstimatorInput baro(double s) { return BaroSample{at(s), 97000.0}; }

/// Pushes an input at `s` at its place, with a context whose last_zupt marks it.
void store(InputTimeline& tl, double s) {
  const EstimatorInput in = baro(s);
  auto ctx = std::make_shared<FilterContext>();
  ctx->last_zupt = at(s);
  tl.window().insert(tl.placeOf(inputOrder(in)), {inputOrder(in), in, ctx});
  tl.advance(at(s));
}

RefineOptions refine(double max_history_s) {
  RefineOptions r;
  r.max_history_s = max_history_s;
  return r;
}

}  // namespace

TEST(InputTimeline, AnInputGoesBetweenItsNeighboursAndIsFoundByItsKey) {
  Diagnostics diag;
  InputTimeline tl(1.0, refine(8.0), false, diag);
  for (double s : {1.0, 1.2, 1.1, 1.15}) store(tl, s);
  ASSERT_EQ(tl.window().size(), 4u);
  std::vector<int64_t> times_us;
  for (const auto& e : tl.window()) times_us.push_back(e.key.t_us);
  EXPECT_EQ(times_us, (std::vector<int64_t>{at(1.0).us, at(1.1).us, at(1.15).us, at(1.2).us}));
  const auto it = tl.find(inputOrder(baro(1.15)));
  ASSERT_NE(it, tl.window().end());
  EXPECT_DOUBLE_EQ(it->before->last_zupt.sec(), 1.15);
  EXPECT_EQ(tl.find(inputOrder(baro(1.3))), tl.window().end());
  // The newest time only moves forward.
  EXPECT_DOUBLE_EQ(tl.newest()->sec(), 1.2);
}

TEST(InputTimeline, WindowAndStartBoundWhatIsAdmitted) {
  Diagnostics diag;
  InputTimeline tl(1.0, refine(8.0), false, diag);
  EXPECT_FALSE(tl.beforeWindow(at(0.0)));  // nothing seen yet: no bound
  tl.advance(at(10.0));
  EXPECT_FALSE(tl.beforeWindow(at(9.0)));  // exactly a window behind
  EXPECT_TRUE(tl.beforeWindow(at(8.99)));
  tl.restart(at(9.5));
  EXPECT_DOUBLE_EQ(tl.start().sec(), 9.5);
  tl.forgetNewest();
  EXPECT_FALSE(tl.newest());
}

TEST(InputTimeline, WithoutReRunsRetiredInputsAreDropped) {
  Diagnostics diag;
  InputTimeline tl(1.0, refine(8.0), false, diag);
  for (int k = 0; k <= 30; ++k) store(tl, 0.1 * k);
  tl.retire(at(2.0));
  EXPECT_EQ(tl.window().size(), 11u);  // 2.0 … 3.0
  EXPECT_TRUE(tl.archive().empty());
  // The stillness a replay may need: a window and a second.
  EXPECT_EQ(tl.oldestReplayUs(at(10.0).us), at(8.0).us);
}

TEST(InputTimeline, RetiredInputsAreArchivedWithACheckpointEveryEighthOfTheHistory) {
  Diagnostics diag;
  InputTimeline tl(1.0, refine(8.0), true, diag);  // checkpoints every 1 s
  for (int k = 0; k <= 40; ++k) store(tl, 0.1 * k);
  tl.retire(at(3.0));
  ASSERT_EQ(tl.archive().size(), 30u);  // 0.0 … 2.9
  std::vector<double> checkpoints;
  for (const auto& a : tl.archive())
    if (a.checkpoint) {
      checkpoints.push_back(Timestamp{a.key.t_us}.sec());
      EXPECT_DOUBLE_EQ(a.checkpoint->last_zupt.sec(), checkpoints.back()) << "the context before that input";
    }
  ASSERT_EQ(checkpoints.size(), 3u);
  EXPECT_DOUBLE_EQ(checkpoints[0], 0.0);  // the oldest always
  EXPECT_NEAR(checkpoints[1], 1.0, 1e-9);
  EXPECT_NEAR(checkpoints[2], 2.0, 1e-9);
  EXPECT_EQ(diag.get("rerun_history_cut"), 0);
  EXPECT_EQ(tl.oldestReplayUs(at(10.0).us), at(1.0).us);  // re-runs reach max_history_s back
}

TEST(InputTimeline, TheArchiveIsCutToTheNextCheckpointBehindTheLimitAndCounted) {
  Diagnostics diag;
  InputTimeline tl(1.0, refine(8.0), true, diag);
  for (int k = 0; k <= 100; ++k) {
    store(tl, 0.1 * k);
    tl.retire(*tl.newest() - Duration::fromSec(1.0));
  }
  // At t = 10 s the limit is 2 s: the archive starts at the first checkpoint at or after it.
  ASSERT_FALSE(tl.archive().empty());
  const auto& front = tl.archive().front();
  EXPECT_TRUE(front.checkpoint) << "a re-run needs the state before its first input";
  EXPECT_GE(Timestamp{front.key.t_us}.sec(), 2.0 - 1e-9);
  EXPECT_LT(Timestamp{front.key.t_us}.sec(), 3.0 + 1e-9);
  EXPECT_GT(diag.get("rerun_history_cut"), 0);
  EXPECT_GT(diag.get("rerun_inputs_cut"), 0);
}

TEST(InputTimeline, RestartForgetsWindowAndArchiveClearKeepsTheStart) {
  Diagnostics diag;
  InputTimeline tl(1.0, refine(8.0), true, diag);
  for (int k = 0; k <= 30; ++k) store(tl, 0.1 * k);
  tl.retire(at(2.0));
  ASSERT_FALSE(tl.archive().empty());
  tl.restart(at(3.0));
  EXPECT_TRUE(tl.window().empty());
  EXPECT_TRUE(tl.archive().empty());
  EXPECT_DOUBLE_EQ(tl.start().sec(), 3.0);
  store(tl, 3.1);
  tl.clear();
  EXPECT_TRUE(tl.window().empty());
  EXPECT_DOUBLE_EQ(tl.start().sec(), 3.0);
  EXPECT_DOUBLE_EQ(tl.newest()->sec(), 3.1);  // the clock stays
}
