/// AnchorRerun (estimator/refine/anchor_rerun.h) as a part, on a fake replayer: which joins make a
/// re-run due, the loose prior, the job taken from the timeline, its computation (order, priors,
/// returned contexts, cancel) and an inline re-run refreshing every stored context. The re-run's
/// effect on a real flight is tested on the node (test_anchor_rerun.cpp, test_anchor_rerun_async.cpp).
#include <gtest/gtest.h>

#include "estimator/filter/strategy_factory.h"
#include "estimator/refine/anchor_rerun.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

Timestamp at(double s) { return Timestamp::fromSec(s); }

constexpr SensorId kImu = 1, kAnchor = 106;

/// A context at `s` whose filter has the IMU and, with `anchor`, anchor 106.
std::shared_ptr<FilterContext> contextAt(double s, bool anchor) {
  auto c = std::make_shared<FilterContext>();
  c->filter = makeStrategy(EstimatorOptions{});
  c->filter->reset(kImu, ImuState{}, ImuMatrix::Identity(), at(s));
  if (anchor) c->filter->addInstance<AnchorKind>(kAnchor, AnchorState{Eigen::Vector3d(1, 2, 3)}, Eigen::Matrix3d::Identity());
  c->last_zupt = at(s);
  return c;
}

AnchorInit calibrated(double s) {
  AnchorInit a;
  a.t = at(s);
  a.id = kAnchor;
  a.p_AinG = {4.0, 5.0, 2.0};
  a.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.01;
  PairBias b;
  b.a = 101;
  b.b = kAnchor;
  b.gamma_m = 0.2;
  b.sigma_gamma_m = 0.05;
  a.biases = {b};
  a.cov_gamma_m2 = Eigen::MatrixXd::Constant(1, 1, 0.0025);
  a.cov_gamma_p_m2 = Eigen::MatrixXd::Zero(1, 3);
  return a;
}

/// Replays by stamping the context with the input's time; adds anchors as the node would.
struct FakeReplayer final : RerunReplayer {
  FilterContext ctx;
  std::vector<double> replayed_s;
  std::vector<AnchorInit> anchors;
  FilterContext& replayContext() override { return ctx; }
  std::optional<double> nextImuSpan_s() const override { return std::nullopt; }
  void replay(const EstimatorInput& in, const std::optional<ImuSample>&) override {
    replayed_s.push_back(inputTime(in).sec());
    ctx.last_zupt = inputTime(in);
  }
  void replayAnchor(const AnchorInit& a) override {
    anchors.push_back(a);
    ctx.filter->addInstance<AnchorKind>(a.id, AnchorState{a.p_AinG}, a.cov_p_m2);
  }
};

/// A timeline with inputs every 0.1 s over [0, 4] s, the window 1 s (archived before it).
InputTimeline storedTimeline(Diagnostics& diag) {
  RefineOptions r;
  r.max_history_s = 8.0;
  InputTimeline tl(1.0, r, true, diag);
  for (int k = 0; k <= 40; ++k) {
    const EstimatorInput in = BaroSample{at(0.1 * k), 97000.0};
    tl.window().push_back({inputOrder(in), in, contextAt(0.1 * k, false)});
    tl.advance(at(0.1 * k));
    tl.retire(*tl.newest() - Duration::fromSec(1.0));
  }
  return tl;
}

}  // namespace

TEST(AnchorRerunPart, OnlyALiveJoinOfAnAnchorTheFilterTookMakesAReRunDue) {
  Diagnostics diag;
  StepTimings timings;
  AnchorRerun r(EstimatorOptions{}, diag, timings);
  ASSERT_TRUE(r.enabled());
  const auto without = contextAt(1.0, false), with = contextAt(1.0, true);
  r.noteJoin(calibrated(1.0), true, *without->filter);  // refused by the filter: nothing to refine
  EXPECT_FALSE(r.pending());
  r.noteJoin(calibrated(1.0), false, *with->filter);  // a replay of the join
  EXPECT_FALSE(r.pending());
  r.setApplyingHeld(true);  // anchors held before the initialization keep their covariance
  r.noteJoin(calibrated(1.0), true, *with->filter);
  EXPECT_FALSE(r.pending());
  r.setApplyingHeld(false);
  r.noteJoin(calibrated(1.0), true, *with->filter);
  EXPECT_TRUE(r.pending());
  // Replayed later, its ANCHOR_INIT is skipped: the anchor is in the state with the loose prior.
  EXPECT_TRUE(r.skipReplayed(calibrated(1.0), false, *with->filter));
  EXPECT_FALSE(r.skipReplayed(calibrated(1.0), true, *with->filter));
  r.forget(kAnchor);
  EXPECT_FALSE(r.skipReplayed(calibrated(1.0), false, *with->filter));
  r.reset();
  EXPECT_FALSE(r.pending());
}

TEST(AnchorRerunPart, OffForDahUnlessAskedAndWhenSwitchedOff) {
  Diagnostics diag;
  StepTimings timings;
  EstimatorOptions o;
  o.strategy = "dah";
  o.refine.rerun_with_dah = false;
  EXPECT_FALSE(AnchorRerun(o, diag, timings).enabled());
  o.refine.rerun_with_dah = true;
  EXPECT_TRUE(AnchorRerun(o, diag, timings).enabled());
  o.refine.rerun_on_anchor_join = false;
  EXPECT_FALSE(AnchorRerun(o, diag, timings).enabled());
}

TEST(AnchorRerunPart, TheLoosePriorIsTheCalibrationsMeanWithRefineSigmas) {
  Diagnostics diag;
  StepTimings timings;
  EstimatorOptions o;
  o.refine.rerun_prior_sigma_m = 0.3;
  o.refine.rerun_gamma_sigma_m = 0.25;
  const AnchorInit l = AnchorRerun(o, diag, timings).loosePrior(calibrated(9.0), at(2.0));
  EXPECT_DOUBLE_EQ(l.t.sec(), 2.0);
  EXPECT_TRUE(l.p_AinG.isApprox(Eigen::Vector3d(4.0, 5.0, 2.0)));
  EXPECT_TRUE(l.cov_p_m2.isApprox(Eigen::Matrix3d::Identity() * 0.09));
  EXPECT_FALSE(l.hasJointCovariance());
  ASSERT_EQ(l.biases.size(), 1u);
  EXPECT_DOUBLE_EQ(l.biases[0].sigma_gamma_m, 0.25);
  EXPECT_DOUBLE_EQ(l.biases[0].gamma_m, 0.0);  // the calibrator's prior mean
  o.refine.rerun_gamma_from_calibration = true;
  EXPECT_DOUBLE_EQ(AnchorRerun(o, diag, timings).loosePrior(calibrated(9.0), at(2.0)).biases[0].gamma_m, 0.2);
}

TEST(AnchorRerunPart, TheJobStartsAtTheOldestStoredContextAndKeepsCheckpointsAndTheWindow) {
  Diagnostics diag;
  StepTimings timings;
  AnchorRerun r(EstimatorOptions{}, diag, timings);
  InputTimeline empty(1.0, RefineOptions{}, true, diag);
  EXPECT_FALSE(r.makeJob(empty));
  const InputTimeline tl = storedTimeline(diag);
  const auto job = r.makeJob(tl);
  ASSERT_TRUE(job);
  EXPECT_EQ(job->base, tl.archive().front().checkpoint);
  EXPECT_EQ(job->inputs.size(), tl.archive().size() + tl.window().size());
  EXPECT_TRUE(std::is_sorted(job->keys.begin(), job->keys.end()));
  EXPECT_FALSE(job->keep_before.front()) << "the base stays the state without the re-run's anchors";
  size_t kept = 0;
  for (size_t i = 0; i < tl.archive().size(); ++i) {
    EXPECT_EQ(job->keep_before[i] != 0, i > 0 && tl.archive()[i].checkpoint != nullptr) << i;
    kept += job->keep_before[i];
  }
  EXPECT_GE(kept, 2u);  // the checkpoints at 1 s and 2 s
  for (size_t i = tl.archive().size(); i < job->keep_before.size(); ++i) EXPECT_TRUE(job->keep_before[i]);
}

TEST(AnchorRerunPart, ComputeAddsThePriorsAtTheBaseAndReplaysInOrderUntilCancelled) {
  Diagnostics diag;
  StepTimings timings;
  AnchorRerun r(EstimatorOptions{}, diag, timings);
  const InputTimeline tl = storedTimeline(diag);
  RerunJob job = *r.makeJob(tl);
  job.priors = {r.loosePrior(calibrated(3.0), at(0.0))};
  FakeReplayer replayer;
  const std::atomic<bool> never{false};
  const RerunResult res = AnchorRerun::compute(job, replayer, never);
  ASSERT_EQ(replayer.anchors.size(), 1u);
  EXPECT_EQ(res.ids, "106");
  EXPECT_EQ(replayer.replayed_s.size(), job.inputs.size());
  EXPECT_TRUE(std::is_sorted(replayer.replayed_s.begin(), replayer.replayed_s.end()));
  EXPECT_FALSE(res.cancelled);
  // The context before each kept input: stamped with the input before it.
  for (const auto& [key, ctx] : res.before) EXPECT_LT(ctx->last_zupt.us, key.t_us);
  EXPECT_EQ(res.before.size(), static_cast<size_t>(std::count(job.keep_before.begin(), job.keep_before.end(), 1)));
  EXPECT_DOUBLE_EQ(res.state.last_zupt.sec(), 4.0);
  // An anchor already in the base (an earlier re-run's checkpoint) is not added again.
  FakeReplayer again;
  RerunJob with_anchor = job;
  with_anchor.base = contextAt(0.0, true);
  AnchorRerun::compute(with_anchor, again, never);
  EXPECT_TRUE(again.anchors.empty());
  // Cancelled: stops before the first input.
  FakeReplayer stopped;
  const std::atomic<bool> cancel{true};
  EXPECT_TRUE(AnchorRerun::compute(job, stopped, cancel).cancelled);
  EXPECT_TRUE(stopped.replayed_s.empty());
}

TEST(AnchorRerunPart, AnInlineReRunRefreshesEveryStoredContextAndIsCounted) {
  Diagnostics diag;
  StepTimings timings;
  AnchorRerun r(EstimatorOptions{}, diag, timings);  // rerun_mode auto: inline
  InputTimeline tl = storedTimeline(diag);
  r.noteJoin(calibrated(4.0), true, *contextAt(4.0, true)->filter);
  ASSERT_TRUE(r.pending());
  std::vector<const FilterContext*> window_before;
  for (const auto& e : tl.window()) window_before.push_back(e.before.get());
  const auto base = tl.archive().front().checkpoint;
  FakeReplayer live;
  r.start(tl, live, [] { return std::unique_ptr<RerunReplayer>(); });
  EXPECT_FALSE(r.pending());
  EXPECT_FALSE(r.running());
  EXPECT_EQ(diag.get("rerun"), 1);
  EXPECT_EQ(diag.get("rerun_inputs"), static_cast<int64_t>(tl.archive().size() + tl.window().size()));
  EXPECT_EQ(live.anchors.size(), 1u);
  EXPECT_EQ(tl.archive().front().checkpoint, base) << "the base is not replaced";
  for (size_t i = 0; i < tl.window().size(); ++i) EXPECT_NE(tl.window()[i].before.get(), window_before[i]) << i;
  EXPECT_DOUBLE_EQ(live.ctx.last_zupt.sec(), 4.0);  // continues live after the last stored input
  // Nothing stored: skipped and counted.
  InputTimeline empty(1.0, RefineOptions{}, true, diag);
  r.start(empty, live, [] { return std::unique_ptr<RerunReplayer>(); });
  EXPECT_EQ(diag.get("rerun_skipped"), 1);
}
