/// The node with the modular strategies: DP ≡ centralized over a flight (in order and with shuffled
/// arrival), out-of-order = in-order for every strategy, instances removed / re-added / added
/// mid-flight without disturbing the others, invariants after every input.
#include <gtest/gtest.h>

#include <map>

#include "modular_test_helpers.h"
#include "estimator/filter/strategy_factory.h"
#include "node_test_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

synthetic::SyntheticOptions scenario(double duration_s = 14.0) {
  synthetic::SyntheticOptions o;
  o.duration_s = duration_s;
  o.landed_s = 3.0;
  o.noise = true;
  o.n_estimated_anchors = 3;  // 106, 107, 108
  o.estimated_anchor_sigma_m = 0.2;
  o.seed = 11;
  return o;
}

/// The synthetic setup with tag–anchor γ states (σ_γ > 0 on the a-priori pairs) and the estimated
/// anchors' priors perturbed by their σ.
Dataset dataset(double duration_s = 14.0) {
  Dataset ds = synthetic::makeSyntheticDataset(scenario(duration_s));
  for (auto& pb : ds.setup.pair_biases) pb.sigma_gamma_m = 0.03;
  ds.setup.abs_anchor_positions[106] += Eigen::Vector3d(0.15, -0.1, 0.05);
  ds.setup.abs_anchor_positions[107] += Eigen::Vector3d(-0.1, 0.2, -0.1);
  ds.setup.abs_anchor_positions[108] += Eigen::Vector3d(0.05, 0.1, 0.2);
  return ds;
}

/// Mean NEES of the IMU position against the synthetic trajectory over the IMU steps after `from_s`.
struct NeesAcc {
  double sum = 0.0;
  int n = 0;
  double mean() const { return n ? sum / n : 0.0; }
};

}  // namespace

TEST(ModularNode, DpEqualsCentralizedStepByStep) {
  const Dataset ds = dataset();
  const auto inputs = mergeInTimeOrder(ds);
  EstimatorNode c(test::strategyOptions("centralized"), ds.setup), dp(test::strategyOptions("dp"), ds.setup);
  double worst = 0.0;
  for (size_t i = 0; i < inputs.size(); ++i) {
    c.onInput(inputs[i]);
    dp.onInput(inputs[i]);
    if (c.initialized() && (i % 50 == 0 || i + 1 == inputs.size()))
      worst = std::max(worst, test::relativeDifference(*dp.filter(), *c.filter()));
  }
  ASSERT_TRUE(dp.initialized());
  EXPECT_GT(dp.filter()->layout().blocks().size(), 6u) << "IMU, baro, 3 anchors, 2 tags";
  EXPECT_LE(worst, 1e-9);
  EXPECT_EQ(dp.diagnostics().get("gated_range"), c.diagnostics().get("gated_range"));
}

TEST(ModularNode, OutOfOrderArrivalEqualsInOrderForEveryStrategy) {
  const Dataset ds = dataset();
  const auto inputs = mergeInTimeOrder(ds);
  const auto shuffled = test::shuffledArrival(inputs, 0.4, 2.0, 5);
  for (const std::string s : {"centralized", "dp", "dah"}) {
    EstimatorNode in_order(test::strategyOptions(s), ds.setup), late(test::strategyOptions(s), ds.setup);
    for (const auto& in : inputs) in_order.onInput(in);
    for (const auto& in : shuffled) late.onInput(in);
    ASSERT_TRUE(late.initialized()) << s;
    EXPECT_GT(late.diagnostics().get("out_of_sequence"), 100) << s;
    EXPECT_EQ(late.diagnostics().get("rejected_too_old"), 0) << s;
    EXPECT_LE(test::relativeDifference(*late.filter(), *in_order.filter()), 1e-9) << s;
    EXPECT_LE(test::stateDifference(*late.filter(), *in_order.filter()), 1e-9) << s;
  }
}

TEST(ModularNode, InvariantsHoldAfterEveryInput) {
  const Dataset ds = dataset(8.0);
  for (const std::string s : {"dp", "dah"}) {
    EstimatorNode node(test::strategyOptions(s), ds.setup);
    int checked = 0;
    for (const auto& in : mergeInTimeOrder(ds)) {
      node.onInput(in);
      if (!node.initialized()) continue;
      ASSERT_NO_THROW(node.filter()->checkInvariants()) << s << " at t=" << inputTime(in).sec();
      ++checked;
    }
    EXPECT_GT(checked, 1000) << s;
  }
}

TEST(ModularNode, RemoveThenReAddAnInstance) {
  const Dataset ds = dataset();
  const auto inputs = mergeInTimeOrder(ds);
  for (const std::string s : {"dp", "dah"}) {
    EstimatorNode node(test::strategyOptions(s), ds.setup);
    bool removed = false, readded = false;
    for (const auto& in : inputs) {
      const double t = inputTime(in).sec();
      if (!removed && t >= 7.0) {
        EstimatorCommand rm;
        rm.t = Timestamp::fromSec(t);
        rm.action = EstimatorCommand::Action::RemoveInstance;
        rm.id = 107;
        node.onCommand(rm);
        removed = true;
        EXPECT_FALSE(node.filter()->layout().find(107)) << s;
        EXPECT_FALSE(node.filter()->state().values<AnchorKind>().count(107)) << s;
        node.filter()->checkInvariants();
      }
      if (!readded && t >= 9.0) {
        EstimatorCommand add;
        add.t = Timestamp::fromSec(t);
        add.action = EstimatorCommand::Action::AddAnchor;
        add.id = 107;
        add.anchor.id = 107;
        add.anchor.p_AinG = synthetic::syntheticAnchors(3).at(107) + Eigen::Vector3d(0.1, -0.1, 0.05);
        add.anchor.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.04;
        node.onCommand(add);
        readded = true;
        ASSERT_TRUE(node.filter()->layout().find(107)) << s;
        EXPECT_TRUE(node.filter()->covariance(1, 107).isZero(0.0)) << s << ": re-added uncorrelated";
      }
      node.onInput(in);
    }
    ASSERT_TRUE(readded);
    node.filter()->checkInvariants();
    // Ranges to 107 between removal and re-adding were unknown; afterwards it is fused again.
    EXPECT_GT(node.diagnostics().get("unknown_id"), 0) << s;
    const Eigen::Vector3d err = node.filter()->state().values<AnchorKind>().at(107).p_AinG - synthetic::syntheticAnchors(3).at(107);
    const Eigen::Matrix3d P = node.filter()->covariance(107, 107);
    EXPECT_LT(err.dot(P.ldlt().solve(err)), 16.27) << s << ": NEES of the re-added anchor (χ²(3) 99.9 %)";
    EXPECT_LT(err.norm(), 0.1) << s;
  }
}

TEST(ModularNode, InstancesAddedAndRemovedMidFlightKeepTheOthersConsistent) {
  Dataset ds = dataset(20.0);
  // Anchor 108 is unknown at start (ANCHOR_INIT at 8 s); 106 is removed at 12 s.
  const Eigen::Vector3d p108 = ds.setup.abs_anchor_positions.at(108);
  ds.setup.abs_anchor_positions.erase(108);
  ds.setup.abs_anchor_sigmas_m.erase(108);
  const auto inputs = mergeInTimeOrder(ds);
  const synthetic::SyntheticTrajectory traj(3.0, 30.0 * M_PI / 180.0);
  for (const std::string s : {"centralized", "dp", "dah"}) {
    EstimatorNode node(test::strategyOptions(s), ds.setup);
    bool added = false, removed = false;
    NeesAcc before, after;
    for (const auto& in : inputs) {
      const double t = inputTime(in).sec();
      if (!added && t >= 8.0) {
        AnchorInit a;
        a.t = Timestamp::fromSec(t);
        a.id = 108;
        a.p_AinG = p108;
        a.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.04;
        node.onAnchorInit(a);
        added = true;
      }
      if (!removed && t >= 12.0) {
        EstimatorCommand rm;
        rm.t = Timestamp::fromSec(t);
        rm.action = EstimatorCommand::Action::RemoveInstance;
        rm.id = 106;
        node.onCommand(rm);
        removed = true;
      }
      node.onInput(in);
      if (!std::holds_alternative<ImuSample>(in) || !node.initialized() || t < 4.0) continue;
      const PoseEstimate e = *node.pose();
      const Eigen::Vector3d dp = e.p_IinG - traj.position(t);
      (t < 8.0 ? before : after).sum += dp.dot(e.cov_p_m2.ldlt().solve(dp));
      ++(t < 8.0 ? before : after).n;
    }
    EXPECT_EQ(node.diagnostics().get("anchor_init"), 1) << s;
    EXPECT_FALSE(node.filter()->layout().find(106)) << s;
    ASSERT_TRUE(node.filter()->layout().find(108)) << s;
    node.filter()->checkInvariants();
    std::cout << s << ": position ANEES before 8 s " << before.mean() << ", after " << after.mean() << std::endl;
    EXPECT_LT(after.mean(), 6.0) << s;
    EXPECT_GT(after.mean(), 0.3) << s;
    // Anchor 107 kept its belief through both changes.
    const Eigen::Vector3d err = node.filter()->state().values<AnchorKind>().at(107).p_AinG - synthetic::syntheticAnchors(3).at(107);
    EXPECT_LT(err.dot(node.filter()->covariance(107, 107).ldlt().solve(err)), 16.27) << s;
    const Eigen::Vector3d err108 = node.filter()->state().values<AnchorKind>().at(108).p_AinG - synthetic::syntheticAnchors(3).at(108);
    EXPECT_LT(err108.norm(), 0.1) << s;
  }
}

TEST(ModularNode, StatusReportsInstancesTimingsAndCounters) {
  const Dataset ds = dataset(8.0);
  EstimatorNode node(test::strategyOptions("dah"), ds.setup);
  for (const auto& in : test::shuffledArrival(mergeInTimeOrder(ds), 0.3, 2.0, 2)) node.onInput(in);
  RangeSample old = ds.ranges.back();
  old.t = Timestamp::fromSec(1.0);  // beyond the window
  node.onRange(old);
  const EstimatorStatus st = node.status();
  EXPECT_EQ(st.strategy, "dah");
  EXPECT_GT(st.counters.at("out_of_sequence"), 0);
  EXPECT_EQ(st.counters.at("rejected_too_old"), 1);
  for (const char* step : {"propagate", "range_update", "baro_update", "zupt", "rewind"})
    EXPECT_TRUE(st.mean_step_us.count(step)) << step;
  int anchors = 0;
  for (const auto& i : st.instances) {
    if (i.type == "anchor") ++anchors;
    if (i.id == 1) {
      EXPECT_GT(i.n_updates, 0);
    }
  }
  EXPECT_EQ(anchors, 7);  // 101–104 exact, 106–108 estimated
  std::map<SensorId, int> seen;
  for (const auto& i : st.instances) ++seen[i.id];
  for (const auto& [id, n] : seen) EXPECT_EQ(n, 1) << "instance " << id << " listed " << n << " times";
  EXPECT_TRUE(seen.count(100) && seen.count(105)) << "both tags are instances";
}

TEST(ModularNode, DahLeavesRangesBetweenEstimatedAnchorsOutUnlessAsked) {
  const Dataset ds = dataset(8.0);
  int pairs = 0;  // ranges between two estimated anchors (106–108)
  for (const auto& r : ds.ranges) pairs += r.id_initiator >= 106 && r.id_responder >= 106;
  ASSERT_GT(pairs, 10);
  auto run = [&](const std::string& strategy, bool fuse) {
    EstimatorOptions o = test::strategyOptions(strategy);
    o.uwb.dah_fuse_estimated_anchor_pairs = fuse;
    EstimatorNode node(o, ds.setup);
    for (const auto& in : mergeInTimeOrder(ds)) node.onInput(in);
    EXPECT_TRUE(node.initialized());
    return node.diagnostics().get("range_dah_anchor_pair_skipped");
  };
  const int64_t skipped = run("dah", false);
  EXPECT_GT(skipped, 0);
  EXPECT_LE(skipped, pairs);  // those before initialization are not reached
  EXPECT_EQ(run("dah", true), 0);
  EXPECT_EQ(run("dp", false), 0) << "DP and centralized are exact: they always fuse them";
  EXPECT_EQ(run("centralized", false), 0);
}

// The relative comparison goes over every registered kind: a height bias that differs (not named
// by the helper before issue 11) is seen, with its magnitude in the denominator.
TEST(ModularNode, RelativeDifferenceSeesEveryRegisteredKind) {
  EstimatorOptions o;
  o.strategy = "dp";
  auto a = makeStrategy(o);
  a->reset(1, ImuState{}, ImuMatrix::Identity(), Timestamp{});
  a->addInstance<HeightBiasKind>(3, 0.3, Eigen::MatrixXd::Constant(1, 1, 0.01));
  auto b = a->clone();
  EXPECT_EQ(test::relativeDifference(*a, *b), 0.0);
  b->addInstance<HeightBiasKind>(3, 0.2, Eigen::MatrixXd::Constant(1, 1, 0.01));
  EXPECT_NEAR(test::relativeDifference(*a, *b), 0.1 / 1.3, 1e-12);
}
