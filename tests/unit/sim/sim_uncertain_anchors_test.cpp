/// makeAnchorsUncertain: which anchors are perturbed, with what σ, which pair biases are added.
#include <gtest/gtest.h>

#include "sim/scenario_simulator.h"
#include "sim/uncertain_anchors.h"

using namespace meshnav;
using namespace meshnav::sim;

namespace {

SimulationResult shortSequence() {
  SimulationOptions so;
  so.seed = 4;
  so.duration_scale = 0.2;
  return ScenarioSimulator(so).run();
}

}  // namespace

TEST(UncertainAnchors, PerturbsOnlyTheAnchorsThatAreNotKnown) {
  SimulationResult r = shortSequence();
  const SystemSetup before = r.dataset.setup;
  ASSERT_EQ(before.abs_anchor_positions.size(), 4u);  // 101–104
  UncertainAnchorOptions o;
  o.sigma_m = 0.3;
  o.seed = 4;
  EXPECT_EQ(makeAnchorsUncertain(r.dataset, o, SimulationOptions{}.hardware, 0.1), 5);
  const SystemSetup& s = r.dataset.setup;
  for (SensorId id : {101, 102, 103, 104}) {
    EXPECT_EQ(s.abs_anchor_positions.at(id), before.abs_anchor_positions.at(id)) << id;
    EXPECT_FALSE(s.abs_anchor_sigmas_m.count(id)) << id;
  }
  double sq = 0.0;
  for (SensorId id : {106, 107, 108, 109, 110}) {
    ASSERT_TRUE(s.abs_anchor_positions.count(id)) << id;
    EXPECT_DOUBLE_EQ(s.abs_anchor_sigmas_m.at(id), 0.3);
    const Eigen::Vector3d e = s.abs_anchor_positions.at(id) - r.dataset.truth->anchor_positions.at(id);
    EXPECT_GT(e.norm(), 1e-6) << id;
    EXPECT_LT(e.cwiseAbs().maxCoeff(), 5 * 0.3) << id;
    sq += e.squaredNorm();
  }
  EXPECT_GT(sq / 15.0, 0.3 * 0.3 / 8.0);  // not a vanishing perturbation
  // Every pair with an anchor now has an a-priori bias; tag–tag pairs are left as they were.
  for (SensorId a : {100, 105, 101, 106, 110}) {
    for (SensorId b : {107, 108, 109, 103}) {
      if (a != b) {
        EXPECT_TRUE(s.findPairBias(a, b).has_value()) << a << "-" << b;
      }
    }
  }
  EXPECT_EQ(s.findPairBias(100, 105).has_value(), before.findPairBias(100, 105).has_value());
  EXPECT_GT(s.pair_biases.size(), before.pair_biases.size());
  // Pairs setup.yaml already had are not replaced.
  for (const PairBias& b : before.pair_biases) {
    const std::optional<PairBias> now = s.findPairBias(b.a, b.b);
    ASSERT_TRUE(now.has_value());
    EXPECT_EQ(now->gamma_m, b.gamma_m);
  }
}

TEST(UncertainAnchors, IncludeKnownPerturbsAllWithTheSameErrorsFor106To110) {
  SimulationResult a = shortSequence(), b = shortSequence();
  UncertainAnchorOptions o;
  o.seed = 4;
  makeAnchorsUncertain(a.dataset, o, SimulationOptions{}.hardware, 0.1);
  o.include_known = true;
  EXPECT_EQ(makeAnchorsUncertain(b.dataset, o, SimulationOptions{}.hardware, 0.1), 9);
  EXPECT_EQ(b.dataset.setup.abs_anchor_sigmas_m.size(), 9u);
  EXPECT_NE(b.dataset.setup.abs_anchor_positions.at(101), a.dataset.setup.abs_anchor_positions.at(101));
  for (SensorId id : {106, 107, 108, 109, 110})
    EXPECT_EQ(b.dataset.setup.abs_anchor_positions.at(id), a.dataset.setup.abs_anchor_positions.at(id)) << id;
}

TEST(UncertainAnchors, RejectsBadSigmaAndMissingTruth) {
  SimulationResult r = shortSequence();
  UncertainAnchorOptions o;
  o.sigma_m = 0.0;
  EXPECT_THROW(makeAnchorsUncertain(r.dataset, o, {}, 0.1), std::invalid_argument);
  o.sigma_m = 0.3;
  r.dataset.truth.reset();
  EXPECT_THROW(makeAnchorsUncertain(r.dataset, o, {}, 0.1), std::invalid_argument);
}
