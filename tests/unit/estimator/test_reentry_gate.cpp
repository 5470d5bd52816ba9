/// ReentryGate (estimator/uwb/reentry_gate.h) on a real filter: tag ranges pass within
/// reentry_gap_s; after a gap with dense ranging they are held for reentry_hold_s, checked against
/// each other and released from the first held key (the outlier rejected on replay, the others
/// counted on their first replay only); sparse ranging passes; restart and forgetting fates.
#include <gtest/gtest.h>

#include <memory>

#include "estimator/filter/strategy_factory.h"
#include "estimator/uwb/reentry_gate.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

Timestamp at(double s) { return Timestamp::fromSec(s); }

constexpr SensorId kTag = 100;
const std::map<SensorId, Eigen::Vector3d> kAnchors = {
    {101, {5.0, 0.0, 3.0}}, {102, {0.0, 5.0, 3.0}}, {103, {-5.0, 0.0, 2.5}}, {104, {0.0, -5.0, 2.5}}, {106, {4.0, 4.0, 0.2}}};

/// A gate with the default re-entry options (gap 2 s, hold 0.5 s, 4 ranges from 3 anchors) and a
/// filter at (0, 0, 1) m with a wide position prior (σ 0.6 m): every range sees the same
/// dead-reckoning error kError, plus `excess` [m].
struct Scene {
  UwbOptions uwb;
  Diagnostics diag;
  ReentryGate gate{uwb, diag};
  std::unique_ptr<FusionStrategy> filter = makeStrategy(EstimatorOptions{});
  const Eigen::Vector3d p{0.0, 0.0, 1.0}, kError{0.5, -0.4, 0.3};

  Scene() {
    ImuState x;
    x.p_IinG = p;
    ImuMatrix P = ImuMatrix::Identity() * 0.01;
    P.block<3, 3>(ImuErr::kP, ImuErr::kP) = Eigen::Matrix3d::Identity() * 0.36;
    filter->reset(1, x, P, at(0.0));
  }
  static RangeSample range(double t, SensorId anchor) {
    RangeSample r;
    r.t = at(t);
    r.id_initiator = kTag;
    r.id_responder = anchor;
    r.range_m = r.range_corr_m = 5.0;
    return r;
  }
  Linearization lin(SensorId anchor, double excess) const {
    const Eigen::Vector3d u = (p - kAnchors.at(anchor)).normalized();  // ∂h/∂p: anchor → tag
    Linearization l;
    l.residual = Eigen::VectorXd::Constant(1, u.dot(kError) + excess);
    l.R = Eigen::MatrixXd::Constant(1, 1, 0.01);
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(1, ImuErr::kDim);
    H.block<1, 3>(0, ImuErr::kP) = u.transpose();
    l.blocks.push_back({1, H});
    return l;
  }
  /// admit() of the range at `t` to `anchor` (init time 0).
  bool admit(double t, SensorId anchor, bool first, bool* count = nullptr, double excess = 0.0) {
    bool unused = false;
    return gate.admit(range(t, anchor), anchor, lin(anchor, excess), *filter, at(0.0), first, count ? count : &unused);
  }
  /// The k-th range of a 20 Hz round over the anchors.
  static SensorId anchorOf(int k) { return std::next(kAnchors.begin(), k % 5)->first; }
  /// Ranges every 50 ms over [from, to), each accepted (noteAccepted) when it passes.
  void rangesAccepted(double from, double to) {
    for (int k = 0; from + 0.05 * k < to - 1e-9; ++k) {
      const double t = from + 0.05 * k;
      ASSERT_TRUE(admit(t, anchorOf(k), true)) << t;
      gate.noteAccepted(at(t));
    }
  }
};

InputOrder keyOf(double t, SensorId anchor) { return inputOrder(EstimatorInput(Scene::range(t, anchor))); }

}  // namespace

TEST(ReentryGate, RangesWithinTheGapPassAndDenseOnesAfterItAreHeld) {
  Scene s;
  s.rangesAccepted(0.1, 2.0);  // the last accepted at 1.95
  EXPECT_FALSE(s.gate.holding());
  EXPECT_EQ(s.diag.get("range_reentry_held"), 0);
  // 1.99 s after the last accepted one: still within the gap.
  EXPECT_TRUE(s.admit(3.94, 101, true));
  // No range accepted for 2.05 s: the next ones are held.
  for (int k = 0; k < 10; ++k) EXPECT_FALSE(s.admit(4.0 + 0.05 * k, Scene::anchorOf(k), true)) << k;
  EXPECT_TRUE(s.gate.holding());
  EXPECT_EQ(s.diag.get("range_reentry_hold"), 1);
  EXPECT_EQ(s.diag.get("range_reentry_held"), 10);
  // A rewind replays a held range: still held.
  EXPECT_FALSE(s.admit(4.05, Scene::anchorOf(1), false));
  EXPECT_EQ(s.diag.get("range_reentry_held"), 10);
}

TEST(ReentryGate, ReleaseAfterTheHoldRejectsTheOutlierAndCountsTheOthersOnce) {
  Scene s;
  s.rangesAccepted(0.1, 2.0);
  // Held from 4.0 to 4.45; the third one (4.10, anchor 103) 1 m long (NLOS).
  for (int k = 0; k < 10; ++k) s.admit(4.0 + 0.05 * k, Scene::anchorOf(k), true, nullptr, k == 2 ? 1.0 : 0.0);
  ASSERT_EQ(s.diag.get("range_reentry_held"), 10);
  EXPECT_FALSE(s.gate.releaseIfDue(at(4.45)));
  EXPECT_FALSE(s.gate.releaseIfDue(at(4.499)));
  EXPECT_TRUE(s.gate.holding());
  const auto first = s.gate.releaseIfDue(at(4.5));
  ASSERT_TRUE(first);
  EXPECT_EQ(*first, keyOf(4.0, Scene::anchorOf(0)));
  EXPECT_FALSE(s.gate.holding());
  EXPECT_EQ(s.diag.get("range_reentry_checked"), 1);
  EXPECT_EQ(s.diag.get("range_reentry_rejected"), 1);
  EXPECT_FALSE(s.gate.releaseIfDue(at(4.6)));  // nothing held any more

  // The node re-processes from 4.0: the outlier is not fused, the others are, counted once.
  for (int k = 0; k < 9; ++k) {  // all but the last one (4.40) replayed
    bool count = false;
    const bool fused = s.admit(4.0 + 0.05 * k, Scene::anchorOf(k), false, &count);
    EXPECT_EQ(fused, k != 2) << k;
    EXPECT_EQ(count, k != 2) << k;
  }
  for (int k = 0; k < 9; ++k) {  // a second replay (another rewind): the same fates, not counted again
    bool count = false;
    EXPECT_EQ(s.admit(4.0 + 0.05 * k, Scene::anchorOf(k), false, &count), k != 2) << k;
    EXPECT_FALSE(count) << k;
  }
  // The released ranges were accepted: the next range is no re-entry.
  s.gate.noteAccepted(at(4.45));
  EXPECT_TRUE(s.admit(4.55, 101, true));
  EXPECT_EQ(s.diag.get("range_reentry_held"), 10);

  // Forgetting: accepted fates after window_s + 1 s, rejected ones after keep_s + 1 s.
  s.gate.forgetFates(at(6.42), 1.0, 3.0);  // accepted before 4.42 forgotten, rejected kept
  bool count = false;
  EXPECT_FALSE(s.admit(4.10, 103, false, &count));  // still rejected
  EXPECT_TRUE(s.admit(4.45, Scene::anchorOf(9), false, &count));  // never replayed: its first fusion
  EXPECT_TRUE(count);
  s.gate.forgetFates(at(8.2), 1.0, 3.0);  // rejected before 4.2 forgotten too
  count = false;
  EXPECT_TRUE(s.admit(4.10, 103, false, &count));
  EXPECT_FALSE(count);
}

TEST(ReentryGate, AnAcceptedFateForgottenBeforeItsReplayIsNotCounted) {
  Scene s;
  s.rangesAccepted(0.1, 2.0);
  for (int k = 0; k < 10; ++k) s.admit(4.0 + 0.05 * k, Scene::anchorOf(k), true);
  ASSERT_TRUE(s.gate.releaseIfDue(at(4.5)));
  EXPECT_EQ(s.diag.get("range_reentry_rejected"), 0);
  s.gate.forgetFates(at(6.42), 1.0, 3.0);  // 4.0 … 4.40 forgotten, 4.45 kept
  bool count = false;
  EXPECT_TRUE(s.admit(4.40, Scene::anchorOf(8), false, &count));
  EXPECT_FALSE(count);
  EXPECT_TRUE(s.admit(4.45, Scene::anchorOf(9), false, &count));
  EXPECT_TRUE(count);
}

TEST(ReentryGate, SparseRangesAfterAGapPass) {
  Scene s;
  // One range a second (MILUV-like): 0.5 s holds half a range, fewer than reentry_min_ranges.
  for (int k = 0; k < 2; ++k) {
    ASSERT_TRUE(s.admit(0.5 + k, Scene::anchorOf(k), true));
    s.gate.noteAccepted(at(0.5 + k));
  }
  EXPECT_TRUE(s.admit(4.0, 103, true));  // 2.5 s after the last accepted one
  EXPECT_TRUE(s.admit(5.0, 104, true));
  EXPECT_FALSE(s.gate.holding());
  EXPECT_EQ(s.diag.get("range_reentry_too_sparse"), 2);
  EXPECT_EQ(s.diag.get("range_reentry_held"), 0);
}

TEST(ReentryGate, RestartForgetsTheHoldAndSetsTheLastAcceptedTime) {
  Scene s;
  s.rangesAccepted(0.1, 2.0);
  for (int k = 0; k < 5; ++k) s.admit(4.0 + 0.05 * k, Scene::anchorOf(k), true);
  ASSERT_TRUE(s.gate.holding());
  s.gate.restart(at(4.3));  // re-initialized from ranges at 4.3
  EXPECT_FALSE(s.gate.holding());
  EXPECT_FALSE(s.gate.releaseIfDue(at(5.0)));
  EXPECT_TRUE(s.admit(4.05, Scene::anchorOf(1), false));  // a formerly held range replays as any other
  EXPECT_TRUE(s.admit(6.2, 101, true));                   // 1.9 s after 4.3: within the gap
  EXPECT_EQ(s.diag.get("range_reentry_held"), 5);
  // reset() forgets the last accepted time too: the gap is measured from the initialization.
  s.gate.reset();
  EXPECT_TRUE(s.admit(1.5, 101, true));
}

TEST(ReentryGate, OffWithAZeroGap) {
  Scene s;
  s.uwb.reentry_gap_s = 0.0;  // the gate reads the options it was given
  for (int k = 0; k < 40; ++k) EXPECT_TRUE(s.admit(10.0 + 0.05 * k, Scene::anchorOf(k), true));
  EXPECT_FALSE(s.gate.holding());
  EXPECT_EQ(s.diag.total(), 0);
}
