/// The multilateration baseline on noise-free synthetic ranges (exact answer) and its rejections.

#include <gtest/gtest.h>

#include "eval/baseline_evaluation.h"
#include "eval/multilateration.h"

using namespace meshnav;
using namespace meshnav::eval;

namespace {

SystemSetup fiveAnchors() {
  SystemSetup s;
  s.rel_tag_positions[1000] = {0.1, -0.025, 0.0};
  s.abs_anchor_positions = {{7, {0, 0, 0}}, {8, {5.5, 0, 0}}, {9, {2.6, 2.7, 0}}, {10, {5.5, 0.05, 1.86}},
                            {11, {3.1, -2.6, 1.85}}};
  return s;
}

/// Ranges from tag 1000 at `p` to every anchor of `s` at time t (initiator alternating).
void addEpoch(std::vector<RangeSample>& out, const SystemSetup& s, const Eigen::Vector3d& p, double t) {
  bool flip = false;
  for (const auto& [id, a] : s.abs_anchor_positions) {
    RangeSample r;
    r.t = Timestamp::fromSec(t);
    r.id_initiator = flip ? id : 1000;
    r.id_responder = flip ? 1000 : id;
    r.type_initiator = flip ? UwbType::Anchor : UwbType::Tag;
    r.type_responder = flip ? UwbType::Tag : UwbType::Anchor;
    r.range_m = (p - a).norm();
    out.push_back(r);
    flip = !flip;
  }
}

Eigen::Vector3d walk(double t) { return {2.0 + std::cos(t), 0.5 * std::sin(t), 1.0 + 0.1 * t}; }

}  // namespace

TEST(Multilateration, NoiseFreeRangesGiveTheExactPositionAtEveryEpoch) {
  const auto s = fiveAnchors();
  std::vector<RangeSample> ranges;
  for (int k = 0; k < 40; ++k) addEpoch(ranges, s, walk(0.05 * k), 100.0 + 0.05 * k);
  Diagnostics diag;
  Multilateration ml({});
  const auto fixes = ml.solve(ranges, s, diag);
  ASSERT_EQ(fixes.size(), 40u);
  for (int k = 0; k < 40; ++k) {
    EXPECT_EQ(fixes[k].t, Timestamp::fromSec(100.0 + 0.05 * k));
    EXPECT_LT((fixes[k].p_IinG - walk(0.05 * k)).norm(), 1e-9) << "epoch " << k;
  }
  EXPECT_EQ(ml.stats().fixes, 40);
  EXPECT_EQ(diag.total(), 0);
}

TEST(Multilateration, LinearStartIsExactWithoutNoiseAndRefusesCoplanarAnchors) {
  const auto s = fiveAnchors();
  std::vector<Eigen::Vector3d> a;
  std::vector<double> z;
  const Eigen::Vector3d p(1.0, -1.0, 0.7);
  for (const auto& [id, x] : s.abs_anchor_positions) {
    a.push_back(x);
    z.push_back((p - x).norm());
  }
  const auto lin = Multilateration::linearSolution(a, z);
  ASSERT_TRUE(lin);
  EXPECT_LT((*lin - p).norm(), 1e-9);
  for (auto& x : a) x.z() = 0.0;  // all anchors in one plane: height undetermined linearly
  EXPECT_FALSE(Multilateration::linearSolution(a, z));
}

TEST(Multilateration, HuberLossKeepsOneOutlierFromDraggingTheFix) {
  // Six anchors, one range 2 m too long: the Huber fix moves much less than the least-squares one.
  auto s = fiveAnchors();
  s.abs_anchor_positions[12] = {0.0, 3.0, 2.5};
  std::vector<RangeSample> ranges;
  const Eigen::Vector3d p(2.5, 0.3, 1.1);
  addEpoch(ranges, s, p, 5.0);
  ranges[2].range_m += 2.0;
  Multilateration::Options o;
  o.max_rms_residual_m = 2.0;
  Diagnostics diag;
  const auto fixes = Multilateration(o).solve(ranges, s, diag);
  o.huber_k_m = 1e9;  // plain least squares
  const auto plain = Multilateration(o).solve(ranges, s, diag);
  ASSERT_EQ(fixes.size(), 1u);
  ASSERT_EQ(plain.size(), 1u);
  const double robust_err = (fixes[0].p_IinG - p).norm(), plain_err = (plain[0].p_IinG - p).norm();
  EXPECT_GT(plain_err, 0.5);
  EXPECT_LT(robust_err, 0.5 * plain_err);
}

TEST(Multilateration, EpochsWithTooFewAnchorsOrLargeResidualsAreCountedNotSolved) {
  const auto s = fiveAnchors();
  std::vector<RangeSample> ranges;
  addEpoch(ranges, s, walk(0), 1.0);
  ranges.resize(3);                     // epoch at 1.0 s: 3 anchors only
  addEpoch(ranges, s, walk(1), 2.0);    // epoch at 2.0 s: inconsistent ranges
  for (size_t i = 3; i < ranges.size(); ++i) ranges[i].range_m += (i % 2 ? 3.0 : -1.5);
  RangeSample other;                    // a range of another tag is not this vehicle's
  other.t = Timestamp::fromSec(3.0);
  other.id_initiator = 2000;
  other.id_responder = 7;
  other.range_m = 2.0;
  ranges.push_back(other);
  Diagnostics diag;
  Multilateration ml({});
  EXPECT_TRUE(ml.solve(ranges, s, diag).empty());
  EXPECT_EQ(ml.stats().too_few_anchors, 1);
  EXPECT_EQ(ml.stats().large_residual, 1);
  EXPECT_EQ(ml.stats().ranges_used, 8);
  EXPECT_EQ(diag.get("multilateration:too_few_anchors"), 1);
}

TEST(Multilateration, BaselineInARotatedTruthFrameIsExactAfterSe3Alignment) {
  const auto s = fiveAnchors();
  std::vector<RangeSample> ranges;
  std::vector<PoseSample> truth;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.8, Eigen::Vector3d(0.2, 0.1, 1).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(10, -4, 0.5);
  for (int k = 0; k <= 200; ++k) {
    const double tk = 0.01 * k;
    truth.push_back({Timestamp::fromSec(tk), R * walk(tk) + t, Eigen::Quaterniond::Identity()});
    if (k % 5 == 0 && k > 0 && k < 200) addEpoch(ranges, s, walk(tk), tk);
  }
  Diagnostics diag;
  const auto none = evaluateBaseline(ranges, s, truth, {}, AlignmentMode::None, EvalOptions{}, diag);
  const auto se3 = evaluateBaseline(ranges, s, truth, {}, AlignmentMode::Se3, EvalOptions{}, diag);
  ASSERT_EQ(se3.trajectory.n_selected, 39);
  EXPECT_LT(se3.trajectory.position.rmse, 1e-9);
  EXPECT_GT(none.trajectory.position.rmse, 1.0);
}

// Issue 34 item 7: the baseline is scored as tag positions (the truth's pose with the lever arm),
// so a lever arm costs it nothing: a rig turning about z with its tag 0.5 m off the body. Scored
// as the body's position (before), every fix would be 0.5 m off.
TEST(Multilateration, BaselineIsScoredAsTheTruthsTagPositionSoTheLeverArmCostsNothing) {
  auto s = fiveAnchors();
  s.rel_tag_positions[1000] = {0.5, 0.0, 0.0};
  std::vector<RangeSample> ranges;
  std::vector<PoseSample> truth;
  for (int k = 0; k <= 200; ++k) {
    const double tk = 0.01 * k;
    const Eigen::Quaterniond q(Eigen::AngleAxisd(1.5 * tk, Eigen::Vector3d::UnitZ()));
    truth.push_back({Timestamp::fromSec(tk), walk(tk), q});
    if (k % 5 == 0 && k > 0 && k < 200) addEpoch(ranges, s, walk(tk) + q * s.rel_tag_positions.at(1000), tk);
  }
  Diagnostics diag;
  const auto b = evaluateBaseline(ranges, s, truth, {}, AlignmentMode::None, EvalOptions{}, diag);
  ASSERT_EQ(b.trajectory.n_selected, 39);
  EXPECT_LT(b.trajectory.position.rmse, 1e-9);
  // SE(3) alignment fitted on the tag positions: exact too.
  const auto se3 = evaluateBaseline(ranges, s, truth, {}, AlignmentMode::Se3, EvalOptions{}, diag);
  EXPECT_LT(se3.trajectory.position.rmse, 1e-9);
}
