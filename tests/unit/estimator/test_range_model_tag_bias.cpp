// Range model with the tag–anchor bias γ as a state of the tag instance.
#include <gtest/gtest.h>

#include "estimator/filter/centralized_ekf.h"
#include "estimator/uwb/range_model.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

SystemSetup setupWithUncertainBias() {
  SystemSetup s;
  s.rel_tag_positions[100] = {-0.19, 0.105, -0.07};
  s.abs_anchor_positions[101] = {-1.3, -4.1, 0.66};
  PairBias pb{100, 101, 0.2, 1.0, 0.1};
  pb.sigma_gamma_m = 0.02;
  s.pair_biases.push_back(pb);
  return s;
}

NominalState stateWithGamma(double gamma) {
  NominalState x;
  x.imu_id = 1;
  x.imu.p_IinG = {0.5, 1.0, 2.0};
  x.imu.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()));
  x.values<TagBiasKind>()[100] = BiasState{{101}, Eigen::VectorXd::Constant(1, gamma)};
  return x;
}

}  // namespace

TEST(RangeModelTagBias, UsesTheStateGammaWithUnitJacobianAndNoInflation) {
  const SystemSetup setup = setupWithUncertainBias();
  const UwbNetwork net(setup, 0.15);
  const NominalState x = stateWithGamma(0.35);  // differs from the dictionary's 0.2
  const RangeMeasurement z{Timestamp{}, 101, 100, 5.0, 0.0};  // anchor-initiated: either order works
  Linearization lin;
  ASSERT_EQ(RangeModel::linearize(z, x, net, &lin), RangeModel::Status::Ok);
  const auto pred = RangeModel::predict(z, x, net);
  ASSERT_TRUE(pred);
  EXPECT_NEAR(pred->first, pred->second + 0.35, 1e-12);
  EXPECT_NEAR(lin.residual(0), 5.0 - pred->first, 1e-12);
  const JacobianBlock* tag = lin.find(100);
  ASSERT_NE(tag, nullptr);
  ASSERT_EQ(tag->H.cols(), 1);
  EXPECT_DOUBLE_EQ(tag->H(0, 0), 1.0);
  // Numerical derivative of the prediction w.r.t. the γ state.
  NominalState xp = x;
  xp.values<TagBiasKind>().at(100).gamma_m(0) += 1e-6;
  EXPECT_NEAR((RangeModel::predict(z, xp, net)->first - pred->first) / 1e-6, tag->H(0, 0), 1e-6);
  // σ_γ lives in the state, so the noise is the pair's σ only.
  EXPECT_NEAR(lin.R(0, 0), 0.1 * 0.1, 1e-12);
}

TEST(RangeModelTagBias, WithoutStateTheDictionaryGammaInflatesTheNoise) {
  const SystemSetup setup = setupWithUncertainBias();
  const UwbNetwork net(setup, 0.15);
  NominalState x = stateWithGamma(0.0);
  x.values<TagBiasKind>().clear();
  Linearization lin;
  ASSERT_EQ(RangeModel::linearize({Timestamp{}, 100, 101, 5.0, 0.0}, x, net, &lin), RangeModel::Status::Ok);
  EXPECT_EQ(lin.find(100), nullptr);
  EXPECT_NEAR(lin.R(0, 0), 0.1 * 0.1 + 0.02 * 0.02, 1e-12);
  EXPECT_NEAR(RangeModel::predict({Timestamp{}, 100, 101, 5.0, 0.0}, x, net)->first -
                  RangeModel::predict({Timestamp{}, 100, 101, 5.0, 0.0}, x, net)->second,
              0.2, 1e-12);
}

TEST(RangeModelTagBias, EkfLearnsAConstantBiasFromRepeatedRanges) {
  // A stationary IMU with a tight pose prior: repeated ranges with a true γ of 0.25 pull the γ
  // state (prior 0.2 ± 0.02) towards 0.25 and shrink its variance.
  const SystemSetup setup = setupWithUncertainBias();
  const UwbNetwork net(setup, 0.15);
  CentralizedEkf ekf(ImuPropagator(9.81, ImuNoiseOptions{}), KindRandomWalks{}, true);
  ImuState s;
  s.p_IinG = {0.5, 1.0, 2.0};
  ekf.reset(1, s, ImuMatrix::Identity() * 1e-8, Timestamp{});
  ekf.addInstance<TagBiasKind>(100, BiasState{{101}, Eigen::VectorXd::Constant(1, 0.2)}, Eigen::MatrixXd::Constant(1, 1, 0.02 * 0.02));
  const Eigen::Vector3d p_T = s.p_IinG + setup.rel_tag_positions.at(100);
  const double d = (setup.abs_anchor_positions.at(101) - p_T).norm();
  for (int i = 0; i < 400; ++i) {
    Linearization lin;
    ASSERT_EQ(RangeModel::linearize({Timestamp{}, 100, 101, d + 0.25, 0.0}, ekf.state(), net, &lin),
              RangeModel::Status::Ok);
    ASSERT_TRUE(ekf.update(lin, 0.0).accepted);
  }
  EXPECT_NEAR(ekf.state().values<TagBiasKind>().at(100).gamma_m(0), 0.25, 0.005);
  EXPECT_LT(ekf.covariance(100, 100)(0, 0), 0.2 * 0.02 * 0.02);
}

TEST(RangeModelTagBias, AnUnlistedPairIsUnknownNotZero) {
  // Without a γ state (uwb.estimate_tag_biases off) an unlisted tag–anchor pair's a-priori σ_γ
  // (given to the network) inflates its range noise; a listed pair keeps its own.
  SystemSetup setup = setupWithUncertainBias();
  setup.abs_anchor_positions[102] = {3.0, 1.0, 1.5};  // not in pair_biases
  const UwbNetwork net(setup, 0.15, 0.3);
  NominalState x = stateWithGamma(0.0);
  x.values<TagBiasKind>().clear();
  Linearization lin;
  ASSERT_EQ(RangeModel::linearize({Timestamp{}, 100, 102, 3.0, 0.0}, x, net, &lin), RangeModel::Status::Ok);
  EXPECT_NEAR(lin.R(0, 0), 0.15 * 0.15 + 0.3 * 0.3, 1e-12) << "fallback σ, then σ_γ of the unknown pair";
  ASSERT_EQ(RangeModel::linearize({Timestamp{}, 100, 101, 5.0, 0.0}, x, net, &lin), RangeModel::Status::Ok);
  EXPECT_NEAR(lin.R(0, 0), 0.1 * 0.1 + 0.02 * 0.02, 1e-12) << "the listed pair is unchanged";
  const UwbNetwork exact(setup, 0.15);  // 0: unlisted pairs exact
  ASSERT_EQ(RangeModel::linearize({Timestamp{}, 100, 102, 3.0, 0.0}, x, exact, &lin), RangeModel::Status::Ok);
  EXPECT_NEAR(lin.R(0, 0), 0.15 * 0.15, 1e-12);
}
