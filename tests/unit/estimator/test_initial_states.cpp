/// addSetupAnchorStates / addTagBiasStates (estimator/init/initial_states.h): which instances a new
/// filter gets besides the IMU, their means and prior variances, and the options that turn the
/// bias states off.
#include <gtest/gtest.h>

#include "estimator/filter/strategy_factory.h"
#include "estimator/init/initial_states.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

PairBias pair(SensorId a, SensorId b, double gamma, double sigma_gamma) {
  PairBias p;
  p.a = a;
  p.b = b;
  p.gamma_m = gamma;
  p.sigma_gamma_m = sigma_gamma;
  return p;
}

/// Tags 11, 12; exact anchors 101, 102; uncertain anchors 103 (σ 0.2 m) and 104 (σ 0.5 m).
SystemSetup setup() {
  SystemSetup s;
  s.rel_tag_positions = {{11, Eigen::Vector3d::Zero()}, {12, Eigen::Vector3d(0.1, 0, 0)}};
  s.abs_anchor_positions = {{101, Eigen::Vector3d(0, 0, 2)}, {102, Eigen::Vector3d(5, 0, 2)},
                            {103, Eigen::Vector3d(5, 5, 2)}, {104, Eigen::Vector3d(0, 5, 2)}};
  s.abs_anchor_sigmas_m = {{103, 0.2}, {104, 0.5}};
  s.pair_biases = {pair(11, 101, 0.1, 0.05), pair(11, 103, -0.2, 0.1), pair(12, 102, 0.3, 0.0),
                   pair(103, 101, 0.15, 0.04), pair(104, 103, 0.05, 0.02), pair(104, 102, 0.0, 0.0)};
  return s;
}

std::unique_ptr<FusionStrategy> filter() {
  auto f = makeStrategy(EstimatorOptions{});
  f->reset(1, ImuState{}, ImuMatrix::Identity(), Timestamp::fromSec(1.0));
  return f;
}

}  // namespace

TEST(InitialStates, UncertainSetupAnchorsBecomeInstancesWithTheirSigma) {
  UwbOptions o;
  auto f = filter();
  addSetupAnchorStates(*f, setup(), o);
  const auto& anchors = f->state().values<AnchorKind>();
  ASSERT_EQ(anchors.size(), 2u);  // 103 and 104; 101 and 102 are exact
  EXPECT_TRUE(anchors.at(103).p_AinG.isApprox(Eigen::Vector3d(5, 5, 2)));
  EXPECT_TRUE(f->covariance(103, 103).isApprox(Eigen::Matrix3d::Identity() * 0.04));
  EXPECT_TRUE(f->covariance(104, 104).isApprox(Eigen::Matrix3d::Identity() * 0.25));
  EXPECT_TRUE(anchors.at(103).biases.peers.empty()) << "bias states are off by default";
}

TEST(InitialStates, WithSetupAnchorBiasesEachPairHasOneOwner) {
  UwbOptions o;
  o.estimate_setup_anchor_biases = true;
  auto f = filter();
  addSetupAnchorStates(*f, setup(), o);
  const auto& anchors = f->state().values<AnchorKind>();
  // 103 owns its γ towards the exact 101 (σ_γ > 0); 104 owns the one towards the smaller uncertain
  // 103; a pair whose γ is exact (104–102) is no state.
  EXPECT_EQ(anchors.at(103).biases.peers, (std::vector<SensorId>{101}));
  EXPECT_DOUBLE_EQ(anchors.at(103).biases.gamma_m(0), 0.15);
  EXPECT_EQ(anchors.at(104).biases.peers, (std::vector<SensorId>{103}));
  EXPECT_DOUBLE_EQ(f->covariance(104, 104)(3, 3), 0.02 * 0.02);
}

TEST(InitialStates, TagBiasesTowardsAnchorsWithAnUncertainGamma) {
  UwbOptions o;
  o.uncalibrated_gamma_sigma_m = 0.0;  // unlisted pairs exact: only the listed uncertain γ
  auto f = filter();
  addTagBiasStates(*f, setup(), o);
  const auto& tags = f->state().values<TagBiasKind>();
  ASSERT_EQ(tags.size(), 1u);  // tag 12's only pair has an exact γ
  EXPECT_EQ(tags.at(11).peers, (std::vector<SensorId>{101, 103}));
  EXPECT_DOUBLE_EQ(tags.at(11).gamma_m(1), -0.2);
  EXPECT_DOUBLE_EQ(f->covariance(11, 11)(1, 1), 0.01);
  o.estimate_tag_biases = false;
  auto g = filter();
  addTagBiasStates(*g, setup(), o);
  EXPECT_TRUE(g->state().values<TagBiasKind>().empty());
}

TEST(InitialStates, UnlistedPairsShareTheirTagsCommonOffsetAndKeepTheirOwnPart) {
  // γ(tag, a) = c_tag + e(tag, a): the unlisted pairs of one tag have prior covariance
  // σ_c² 11ᵀ + σ² I, a listed uncertain pair keeps its own σ_γ² and is uncorrelated with them, a
  // listed exact pair is no state.
  UwbOptions o;
  o.uncalibrated_gamma_sigma_m = 0.1;
  o.uncalibrated_common_gamma_sigma_m = 0.5;
  auto f = filter();
  addTagBiasStates(*f, setup(), o);
  const auto& tags = f->state().values<TagBiasKind>();
  ASSERT_EQ(tags.size(), 2u);
  // Tag 11: 101 listed (0.1 ± 0.05), 102 unlisted, 103 listed (−0.2 ± 0.1), 104 unlisted.
  EXPECT_EQ(tags.at(11).peers, (std::vector<SensorId>{101, 102, 103, 104}));
  EXPECT_DOUBLE_EQ(tags.at(11).gamma_m(0), 0.1);
  EXPECT_DOUBLE_EQ(tags.at(11).gamma_m(1), 0.0);
  const Eigen::MatrixXd P11 = f->covariance(11, 11);
  EXPECT_DOUBLE_EQ(P11(1, 1), 0.5 * 0.5 + 0.1 * 0.1);
  EXPECT_DOUBLE_EQ(P11(3, 3), 0.5 * 0.5 + 0.1 * 0.1);
  EXPECT_DOUBLE_EQ(P11(1, 3), 0.5 * 0.5) << "two unlisted pairs of one tag share c_tag";
  EXPECT_DOUBLE_EQ(P11(0, 0), 0.05 * 0.05);
  EXPECT_DOUBLE_EQ(P11(0, 1), 0.0) << "a listed pair has its own calibration";
  // Tag 12: 102 listed exact (no state); 101, 103, 104 unlisted.
  EXPECT_EQ(tags.at(12).peers, (std::vector<SensorId>{101, 103, 104}));
  EXPECT_TRUE(f->covariance(12, 12).isApprox(Eigen::Matrix3d::Constant(0.25) + 0.01 * Eigen::Matrix3d::Identity()));
  // Calibrated ranges (setup noise.sigma_gamma: 0): unlisted pairs are exact again.
  EstimatorOptions e;
  NoiseFigures n;
  n.sigma_gamma_m = 0.0;
  e.applySetupNoise(n);
  auto g = filter();
  addTagBiasStates(*g, setup(), e.uwb);
  EXPECT_EQ(g->state().values<TagBiasKind>().at(11).peers, (std::vector<SensorId>{101, 103}));
  EXPECT_EQ(g->state().values<TagBiasKind>().count(12), 0u);
  // The range errors' correlation time comes from the setup too (a simulator's: 0, independent).
  EXPECT_DOUBLE_EQ(e.uwb.range_error_correlation_s, 0.1);  // STAR-loc's, the default
  n.range_correlation_time_s = 0.0;
  e.applySetupNoise(n);
  EXPECT_DOUBLE_EQ(e.uwb.range_error_correlation_s, 0.0);
}
