// The second pass on an anchor join (issue 10, RefineOptions): when ANCHOR_INIT arrives the node
// re-runs from its oldest stored input with the anchor uncertain from there (counted, inputs
// replayed), which refines the anchor with every range it took part in; the history limit cuts
// the stored inputs at a checkpoint and is counted; off, no re-run (dah re-runs with its joint set).
#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include "estimator/node/estimator_node.h"
#include "estimator/testing/synthetic_scenario.h"
#include "node_test_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

constexpr double kJoinS = 24.0;  ///< data time at which the calibrated anchor joins [s]

/// 30 s of the synthetic flight with anchor 106 unknown to the setup (its ranges are there).
struct Case {
  Dataset ds;
  Eigen::Vector3d p_true;
};

Case makeCase() { return {test::flightWithUnknownAnchors(1), synthetic::syntheticAnchors(1).at(106)}; }

/// A calibration 0.2 m off whose covariance says so (σ 0.12 m per axis).
AnchorInit calibration(const Case& c) {
  AnchorInit a;
  a.id = 106;
  a.p_AinG = c.p_true + Eigen::Vector3d(0.12, -0.12, 0.10);
  a.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.12 * 0.12;
  return a;
}

struct Outcome {
  double error_m = 0.0, nees = 0.0;
  int64_t reruns = 0, rerun_inputs = 0, cuts = 0;
};

Outcome run(const Case& c, const EstimatorOptions& opt) {
  EstimatorNode node(opt, c.ds.setup);
  bool sent = false;
  for (const auto& in : mergeInTimeOrder(c.ds)) {
    if (!sent && inputTime(in).sec() >= kJoinS) {
      AnchorInit a = calibration(c);
      a.t = inputTime(in);
      node.onAnchorInit(a);
      sent = true;
    }
    node.onInput(in);
  }
  EXPECT_TRUE(sent);
  const Eigen::Vector3d e = node.filter()->state().values<AnchorKind>().at(106).p_AinG - c.p_true;
  const Eigen::Matrix3d P = node.filter()->covariance(106, 106).topLeftCorner<3, 3>();
  const Diagnostics& d = node.diagnostics();
  return {e.norm(), e.dot(P.ldlt().solve(e)), d.get("rerun"), d.get("rerun_inputs"), d.get("rerun_history_cut")};
}

EstimatorOptions options(const std::string& strategy, bool rerun) {
  EstimatorOptions o = test::testOptions();
  o.strategy = strategy;
  o.refine.rerun_on_anchor_join = rerun;
  return o;
}

}  // namespace

TEST(AnchorRerun, JoinReRunsFromTheStartAndRefinesTheAnchorMore) {
  const Case c = makeCase();
  const size_t n_inputs = mergeInTimeOrder(c.ds).size();
  for (const std::string strategy : {"centralized", "dp"}) {
    const Outcome off = run(c, options(strategy, false));
    const Outcome on = run(c, options(strategy, true));
    EXPECT_EQ(off.reruns, 0) << strategy;
    EXPECT_EQ(on.reruns, 1) << strategy;
    // Everything since the initialization (landed 3 s, so most of the 24 s) was re-processed.
    EXPECT_GT(on.rerun_inputs, static_cast<int64_t>(0.7 * n_inputs * kJoinS / 30.0)) << strategy;
    EXPECT_EQ(on.cuts, 0) << strategy;
    // Off: 6 s of ranges after the join refine the 0.2 m calibration a little; on: 27 s of them,
    // with the anchor estimated jointly with the trajectory.
    EXPECT_LT(on.error_m, 0.5 * off.error_m) << strategy << ": " << on.error_m << " vs " << off.error_m;
    EXPECT_LT(on.error_m, 0.02) << strategy;  // without the re-run 0.055
    EXPECT_LT(on.nees, 16.27) << strategy;  // χ²(3) at 99.9 %
  }
}

TEST(AnchorRerun, DahReRunsByDefaultWithItsJointSetAndCanBeSwitchedOff) {
  const Case c = makeCase();
  const Outcome dflt = run(c, options("dah", true));
  EXPECT_EQ(dflt.reruns, 1);  // refine.rerun_with_dah: true since the joint sets (docs/results.md)
  EstimatorOptions o = options("dah", true);
  o.refine.rerun_with_dah = false;
  const Outcome off = run(c, o);
  EXPECT_EQ(off.reruns, 0);
  // The anchor is in one joint set with the IMU (uwb.dah_joint_imu), so every pose update also
  // corrects it, as in DP: 0.2 m → 0.005 m, against 0.022 m without the re-run.
  EXPECT_LT(dflt.error_m, 0.5 * off.error_m) << dflt.error_m << " vs " << off.error_m;
  EXPECT_LT(dflt.error_m, 0.02);
  EXPECT_LT(dflt.nees, 16.27);  // χ²(3) at 99.9 %
  // Without the IMU in the set (this case has no tag γ states, so the set is the anchor alone)
  // DAH does not correct the anchor on the updates of the pose by the known anchors, and the
  // re-run gains nothing: 0.031 m.
  EstimatorOptions no_imu = options("dah", true);
  no_imu.uwb.dah_joint_imu = false;
  const Outcome lone = run(c, no_imu);
  EXPECT_EQ(lone.reruns, 1);
  EXPECT_GT(lone.error_m, 2.0 * dflt.error_m) << lone.error_m << " vs " << dflt.error_m;
}

TEST(AnchorRerun, HistoryLimitCutsAtACheckpointAndIsCounted) {
  const Case c = makeCase();
  EstimatorOptions o = options("dp", true);
  o.refine.max_history_s = 8.0;  // checkpoints every 1 s
  const Outcome cut = run(c, o);
  EXPECT_EQ(cut.reruns, 1);
  EXPECT_GT(cut.cuts, 0);
  // The re-run started at the first checkpoint within max_history_s of the join: between 7 s and
  // 8 s (plus the input that carried the join) of inputs.
  int64_t n_8s = 0, n_7s = 0;
  for (const auto& in : mergeInTimeOrder(c.ds)) {
    const double t = inputTime(in).sec();
    if (t < kJoinS) n_8s += t >= kJoinS - 8.0, n_7s += t >= kJoinS - 7.0;
  }
  EXPECT_LE(cut.rerun_inputs, n_8s + 2);
  EXPECT_GE(cut.rerun_inputs, n_7s);
  // A longer history than the flight: no cut.
  o.refine.max_history_s = 60.0;
  EXPECT_EQ(run(c, o).cuts, 0);
}

TEST(AnchorRerun, LateInputsAfterAReRunRewindToReRunStatesAndResumedAnchorsDoNotReRun) {
  const Case c = makeCase();
  const auto inputs = mergeInTimeOrder(c.ds);
  EstimatorNode node(options("dp", true), c.ds.setup);
  // Ranges of the 0.5 s before the join, delivered 0.3 s after it (inside the 1 s window): their
  // rewinds restore snapshots from before the join, which the re-run must have refreshed.
  std::vector<EstimatorInput> held;
  bool sent = false;
  for (const auto& in : inputs) {
    const double t = inputTime(in).sec();
    if (!sent && t >= kJoinS) {
      AnchorInit a = calibration(c);
      a.t = inputTime(in);
      node.onAnchorInit(a);
      sent = true;
    }
    if (t >= kJoinS - 0.5 && t < kJoinS && std::holds_alternative<RangeSample>(in)) {
      held.push_back(in);
      continue;
    }
    node.onInput(in);
    if (t >= kJoinS + 0.3 && !held.empty()) {
      for (const auto& h : held) node.onInput(h);
      held.clear();
    }
  }
  const Diagnostics& d = node.diagnostics();
  EXPECT_EQ(d.get("rerun"), 1);
  EXPECT_GT(d.get("out_of_sequence"), 0);
  // The rewinds restored re-run states: the anchor kept the joint estimate from the start.
  EXPECT_LT((node.filter()->state().values<AnchorKind>().at(106).p_AinG - c.p_true).norm(), 0.02);  // without the re-run 0.055
  EXPECT_EQ(node.filter()->layout().at(106).dim, 3);

  // A restart from the checkpoint takes the anchor back with its covariance: no re-run.
  const EstimatorCheckpoint cp = node.checkpoint();
  const Eigen::Matrix3d P = node.filter()->covariance(106, 106).topLeftCorner<3, 3>();
  EstimatorNode again(options("dp", true), c.ds.setup);
  again.resumeFrom(cp);
  for (const auto& in : inputs) {
    if (inputTime(in) >= cp.t) again.onInput(in);
    if (again.initialized()) break;
  }
  ASSERT_TRUE(again.initialized());
  EXPECT_EQ(again.diagnostics().get("rerun"), 0);
  EXPECT_LT((again.filter()->covariance(106, 106).topLeftCorner<3, 3>() - P).norm(), 1e-12);
}
