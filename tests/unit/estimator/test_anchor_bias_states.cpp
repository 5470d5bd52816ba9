// The pair biases γ of an estimated anchor as states of its instance (issue 10): range model
// (Jacobian, priority over a tag's γ, no σ_γ inflation), the strategies' anchor blocks with the
// calibration's joint covariance (DP ≡ centralized, DAH), the node's ANCHOR_INIT path, and the
// consistency that motivates it: with a constant γ error, fixed γ make the anchor overconfident,
// γ states with the joint prior keep it consistent.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <random>

#include "estimator/filter/centralized_ekf.h"
#include "estimator/filter/modular_filter.h"
#include "estimator/node/estimator_node.h"
#include "estimator/testing/synthetic_scenario.h"
#include "estimator/uwb/range_model.h"
#include "node_test_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

/// Tag 100 on the IMU, exact anchors 101–104, anchor 106 estimated; a-priori γ in the dictionary.
SystemSetup smallSetup() {
  SystemSetup s;
  s.rel_tag_positions[100] = {0.2, 0.1, -0.05};
  s.abs_anchor_positions[101] = {-4.0, -4.0, 0.5};
  s.abs_anchor_positions[102] = {4.0, -4.0, 3.0};
  s.abs_anchor_positions[103] = {4.0, 4.0, 0.5};
  s.abs_anchor_positions[104] = {-4.0, 4.0, 3.0};
  for (SensorId k : {100, 101, 102, 103, 104}) s.pair_biases.push_back(PairBias{k, 106, 0.05, 1.0, 0.1, 0.03, 0.0});
  return s;
}

const Eigen::Vector3d kAnchor106(1.0, -2.0, 2.5);

/// A joint prior of [p_106, γ(106, 101..104)] with the structure of a calibration: each γ is
/// anti-correlated with the position along its reference's direction.
Eigen::MatrixXd jointPrior(const SystemSetup& s) {
  Eigen::MatrixXd info = Eigen::MatrixXd::Zero(7, 7);
  int k = 3;
  for (SensorId r : {101, 102, 103, 104}) {
    const Eigen::Vector3d u = (kAnchor106 - s.abs_anchor_positions.at(r)).normalized();
    Eigen::VectorXd j = Eigen::VectorXd::Zero(7);
    j.head<3>() = u;
    j(k++) = 1.0;
    info += j * j.transpose() / (0.02 * 0.02);  // "calibration ranges"
  }
  for (int i = 3; i < 7; ++i) info(i, i) += 1.0 / (0.1 * 0.1);                   // γ prior
  info.topLeftCorner<3, 3>() += Eigen::Matrix3d::Identity() / (0.15 * 0.15);  // moving tags
  return info.inverse();
}

BiasState biasesTo(std::vector<SensorId> peers, double gamma) {
  return BiasState{peers, Eigen::VectorXd::Constant(static_cast<Eigen::Index>(peers.size()), gamma)};
}

}  // namespace

TEST(AnchorBiasStates, RangeModelUsesTheAnchorsGammaWithUnitJacobian) {
  const SystemSetup setup = smallSetup();
  const UwbNetwork net(setup, 0.15);
  NominalState x;
  x.imu_id = 1;
  x.imu.p_IinG = {0.5, 1.0, 1.0};
  x.values<AnchorKind>()[106].p_AinG = kAnchor106;
  x.values<AnchorKind>()[106].biases = BiasState{{100, 102}, Eigen::Vector2d(0.31, -0.12)};
  x.values<TagBiasKind>()[100] = BiasState{{106}, Eigen::VectorXd::Constant(1, 0.9)};  // the anchor's γ has priority
  for (const auto& [z, peer_row, gamma] : {std::make_tuple(RangeMeasurement{Timestamp{}, 100, 106, 5.0, 0.0}, 3, 0.31),
                                           std::make_tuple(RangeMeasurement{Timestamp{}, 106, 102, 5.0, 0.0}, 4, -0.12)}) {
    Linearization lin;
    ASSERT_EQ(RangeModel::linearize(z, x, net, &lin), RangeModel::Status::Ok);
    const auto pred = RangeModel::predict(z, x, net);
    EXPECT_NEAR(pred->first, pred->second + gamma, 1e-12);
    const JacobianBlock* a = lin.find(106);
    ASSERT_NE(a, nullptr);
    ASSERT_EQ(a->H.cols(), 5);
    EXPECT_EQ(lin.find(100), nullptr);  // the tag's γ state is not used for this pair
    for (int c = 0; c < 5; ++c) {       // numerical derivatives: position and both γ
      NominalState xp = x;
      if (c < 3) xp.values<AnchorKind>().at(106).p_AinG(c) += 1e-6;
      else xp.values<AnchorKind>().at(106).biases.gamma_m(c - 3) += 1e-6;
      EXPECT_NEAR((RangeModel::predict(z, xp, net)->first - pred->first) / 1e-6, a->H(0, c), 1e-5) << c;
    }
    EXPECT_EQ(a->H(0, peer_row), 1.0);
    EXPECT_NEAR(lin.R(0, 0), 0.1 * 0.1, 1e-12);  // σ_γ lives in the state
  }
  // A pair without a γ state: the dictionary's γ, σ_γ inflates the noise.
  Linearization lin;
  ASSERT_EQ(RangeModel::linearize({Timestamp{}, 106, 101, 5.0, 0.0}, x, net, &lin), RangeModel::Status::Ok);
  EXPECT_EQ(lin.find(106)->H(0, 3), 0.0);
  EXPECT_EQ(lin.find(106)->H(0, 4), 0.0);
  EXPECT_NEAR(lin.R(0, 0), 0.1 * 0.1 + 0.03 * 0.03, 1e-12);
}

TEST(AnchorBiasStates, StrategiesHoldTheJointBlockAndDpEqualsCentralized) {
  const SystemSetup setup = smallSetup();
  const UwbNetwork net(setup, 0.15);
  const ImuPropagator prop(9.81, ImuNoiseOptions{});
  CentralizedEkf ekf(prop, KindRandomWalks{}, true);
  ModularFilter dp(ModularFilter::Mode::DP, prop, KindRandomWalks{}, true), dah(ModularFilter::Mode::DAH, prop, KindRandomWalks{}, true);
  const Eigen::MatrixXd J = jointPrior(setup);
  ImuState s;
  s.p_IinG = {0.5, 1.0, 1.0};
  std::vector<FusionStrategy*> all = {&ekf, &dp, &dah};
  for (FusionStrategy* f : all) {
    f->reset(1, s, ImuMatrix::Identity() * 0.01, Timestamp{});
    f->addInstance<AnchorKind>(106, AnchorState{kAnchor106, biasesTo({101, 102, 103, 104}, 0.05)}, J);
    EXPECT_EQ(f->layout().at(106).dim, 7);
    EXPECT_LT((f->covariance(106, 106) - J).norm(), 1e-15);
    EXPECT_THROW(f->addInstance<AnchorKind>(107, AnchorState{kAnchor106, biasesTo({101}, 0.0)}, J), std::invalid_argument);
  }
  std::mt19937 rng(3);
  std::normal_distribution<double> n01;
  for (int i = 0; i < 200; ++i) {
    const SensorId peer = i % 2 ? 100 : 101 + (i / 2) % 4;
    const double z = 6.0 + 0.1 * n01(rng);
    for (FusionStrategy* f : all) {
      Linearization lin;
      ASSERT_EQ(RangeModel::linearize({Timestamp{}, peer, 106, z, 0.0}, f->state(), net, &lin),
                RangeModel::Status::Ok);
      f->update(lin, 0.0);
    }
  }
  EXPECT_LT(test::stateDifference(ekf, dp), 1e-9);
  // DAH: tag ranges are joint {IMU, 106}, anchor ranges private {106}: the γ states moved too.
  EXPECT_NE(dah.state().values<AnchorKind>().at(106).biases.gamma_m, biasesTo({101, 102, 103, 104}, 0.05).gamma_m);
  EXPECT_LT(dah.covariance(106, 106).trace(), J.trace());
  dah.checkInvariants();
  dp.checkInvariants();
}

TEST(AnchorBiasStates, ConstantGammaErrorsStayConsistentOnlyAsStates) {
  // Monte Carlo: the anchor's position and γ errors are drawn from the joint prior; 400 ranges to
  // the exact anchors 101–104 (true γ constant). With the γ as states (joint prior) the final
  // NEES of the position is χ²(3); with the γ fixed at their prior means (σ_γ as white noise) the
  // ranges average the noise but not the constant γ errors: overconfident.
  const SystemSetup setup = smallSetup();
  const UwbNetwork net(setup, 0.15);
  const ImuPropagator prop(9.81, ImuNoiseOptions{});
  Eigen::MatrixXd J = jointPrior(setup);
  const Eigen::MatrixXd L = J.llt().matrixL();
  std::mt19937 rng(11);
  std::normal_distribution<double> n01;
  double nees_states = 0.0, nees_fixed = 0.0;
  const int trials = 60;
  for (int trial = 0; trial < trials; ++trial) {
    Eigen::VectorXd w(7);
    for (int i = 0; i < 7; ++i) w(i) = n01(rng);
    const Eigen::VectorXd err = L * w;  // prior mean − truth
    const Eigen::Vector3d p_true = kAnchor106 - err.head<3>();
    const Eigen::Vector4d gamma_true = Eigen::Vector4d::Constant(0.05) - err.tail<4>();
    for (bool states : {true, false}) {
      ModularFilter f(ModularFilter::Mode::DAH, prop, KindRandomWalks{}, true);
      ImuState s;
      f.reset(1, s, ImuMatrix::Identity() * 0.01, Timestamp{});
      if (states)
        f.addInstance<AnchorKind>(106, AnchorState{kAnchor106, biasesTo({101, 102, 103, 104}, 0.05)}, J);
      else
        f.addInstance<AnchorKind>(106, AnchorState{kAnchor106}, J.topLeftCorner<3, 3>());
      for (int i = 0; i < 400; ++i) {
        const SensorId r = 101 + i % 4;
        const double d = (p_true - setup.abs_anchor_positions.at(r)).norm();
        Linearization lin;
        ASSERT_EQ(RangeModel::linearize({Timestamp{}, 106, r, d + gamma_true(r - 101) + 0.1 * n01(rng), 0.0},
                                        f.state(), net, &lin),
                  RangeModel::Status::Ok);
        f.update(lin, 0.0);
      }
      const Eigen::Vector3d e = f.state().values<AnchorKind>().at(106).p_AinG - p_true;
      const double nees = e.dot(f.covariance(106, 106).topLeftCorner<3, 3>().ldlt().solve(e));
      (states ? nees_states : nees_fixed) += nees / trials;
    }
  }
  EXPECT_GT(nees_states, 1.8);
  EXPECT_LT(nees_states, 4.5);
  EXPECT_GT(nees_fixed, 10.0);
}

TEST(AnchorBiasStates, AnchorInitBecomesStatesWithTheJointCovariance) {
  synthetic::SyntheticOptions o;
  o.duration_s = 8.0;
  o.noise = true;
  o.n_estimated_anchors = 1;
  Dataset ds = synthetic::makeSyntheticDataset(o);
  const Eigen::Vector3d p_true = ds.setup.abs_anchor_positions.at(106);
  ds.setup.abs_anchor_positions.erase(106);
  ds.setup.abs_anchor_sigmas_m.erase(106);
  AnchorInit init;
  init.id = 106;
  init.p_AinG = p_true + Eigen::Vector3d(0.05, -0.03, 0.02);
  // Biases towards the tag 100, anchor 101 and 102 (σ_γ 0 for 102: stays a dictionary value).
  init.biases = {PairBias{100, 106, 0.1, 1.0, 0.1, 0.04, 0.0}, PairBias{101, 106, -0.2, 1.0, 0.1, 0.05, 0.0},
                 PairBias{102, 106, 0.0, 1.0, 0.1, 0.0, 0.0}};
  Eigen::MatrixXd J(6, 6);
  J.setIdentity();
  J.diagonal() << 0.01, 0.01, 0.02, 0.0016, 0.0025, 1e-4;
  J(3, 0) = J(0, 3) = -0.002;
  J(4, 2) = J(2, 4) = 0.003;
  J(3, 4) = J(4, 3) = 0.0005;
  init.cov_p_m2 = J.topLeftCorner<3, 3>();
  init.cov_gamma_p_m2 = J.bottomLeftCorner(3, 3);
  init.cov_gamma_m2 = J.bottomRightCorner(3, 3);
  for (bool joint : {true, false}) {
    EstimatorOptions opt = test::testOptions();
    opt.uwb.anchor_bias_joint_covariance = joint;
    opt.refine.rerun_on_anchor_join = false;  // the calibrated belief itself (a re-run loosens it)
    EstimatorNode node(opt, ds.setup);
    bool sent = false;
    for (const auto& in : mergeInTimeOrder(ds)) {
      if (!sent && node.initialized()) {
        init.t = inputTime(in);
        node.onAnchorInit(init);
        sent = true;
        const auto& x = node.filter()->state();
        ASSERT_EQ(x.values<AnchorKind>().at(106).biases.peers, (std::vector<SensorId>{100, 101}));
        const Eigen::MatrixXd C = node.filter()->covariance(106, 106);
        ASSERT_EQ(C.rows(), 5);
        EXPECT_EQ(C(3, 0), joint ? -0.002 : 0.0);
        EXPECT_EQ(C(4, 2), joint ? 0.003 : 0.0);
        EXPECT_DOUBLE_EQ(C(4, 4), 0.0025);
      }
      node.onInput(in);
    }
    ASSERT_TRUE(sent);
    EXPECT_EQ(node.anchors().back().cov_p_m2.rows(), 3);
    // The checkpoint carries the current γ and the joint covariance back.
    const EstimatorCheckpoint c = node.checkpoint();
    ASSERT_EQ(c.anchors.size(), 1u);
    const AnchorInit& a = c.anchors[0];
    EXPECT_TRUE(a.hasJointCovariance());
    EXPECT_EQ(a.jointCovarianceError(), "");
    for (size_t k = 0; k < a.biases.size(); ++k) {
      if (a.biases[k].a == 100) {
        EXPECT_EQ(a.biases[k].gamma_m, node.filter()->state().values<AnchorKind>().at(106).biases.gamma_m(0));
      }
    }
    // … and a restarted node takes it back (the exact pair 102 has a zero row there).
    EstimatorNode again(opt, ds.setup);
    again.resumeFrom(c);
    for (const auto& in : mergeInTimeOrder(ds)) {
      if (inputTime(in) >= c.t) again.onInput(in);
      if (again.initialized()) break;
    }
    ASSERT_TRUE(again.initialized());
    EXPECT_EQ(again.diagnostics().get("bad_input"), 0);
    ASSERT_EQ(again.filter()->layout().at(106).dim, 5);
    if (joint) {  // (without the option the resumed prior is block-diagonal again)
      EXPECT_LT((again.filter()->covariance(106, 106) - node.filter()->covariance(106, 106)).norm(), 1e-12);
    }
  }
  // A joint covariance that is not positive definite is refused as bad input.
  EstimatorNode node(test::testOptions(), ds.setup);
  AnchorInit bad = init;
  bad.cov_gamma_p_m2(0, 0) = 1.0;
  node.onAnchorInit(bad);
  EXPECT_EQ(node.diagnostics().get("bad_input"), 1);
  bad = init;
  bad.cov_gamma_m2.resize(2, 2);
  node.onAnchorInit(bad);
  EXPECT_EQ(node.diagnostics().get("bad_input"), 2);
}

TEST(AnchorBiasStates, SetupAnchorBiasesAndCalibratedPairsFollowTheirOptions) {
  synthetic::SyntheticOptions o;
  o.duration_s = 8.0;
  o.noise = true;
  o.n_estimated_anchors = 2;  // 106, 107 known-but-uncertain in the setup, ranging with each other
  Dataset ds = synthetic::makeSyntheticDataset(o);
  ds.setup.pair_biases.push_back(PairBias{106, 101, 0.1, 1.0, 0.1, 0.02, 0.0});
  ds.setup.pair_biases.push_back(PairBias{107, 106, -0.1, 1.0, 0.1, 0.03, 0.0});
  ds.setup.pair_biases.push_back(PairBias{107, 102, 0.0, 1.0, 0.1, 0.0, 0.0});  // σ_γ 0: no state
  const auto inputs = mergeInTimeOrder(ds);
  for (bool on : {false, true}) {
    EstimatorOptions opt = test::testOptions();
    opt.uwb.estimate_setup_anchor_biases = on;
    EstimatorNode node(opt, ds.setup);
    for (const auto& in : inputs) node.onInput(in);
    const NominalState& x = node.filter()->state();
    EXPECT_EQ(node.filter()->layout().at(106).dim, on ? 4 : 3);
    EXPECT_EQ(node.filter()->layout().at(107).dim, on ? 4 : 3);  // γ(107, 106): the larger id holds it
    if (on) {
      EXPECT_EQ(x.values<AnchorKind>().at(106).biases.peers, std::vector<SensorId>{101});
      EXPECT_EQ(x.values<AnchorKind>().at(107).biases.peers, std::vector<SensorId>{106});
      EXPECT_LT(node.filter()->covariance(107, 107)(3, 3), 0.03 * 0.03);  // learned from the 106–107 ranges
    }
  }
  // Two anchors that came from ANCHOR_INIT: their mutual ranges are left out on request.
  Dataset dc = ds;
  for (SensorId id : {106, 107}) dc.setup.abs_anchor_positions.erase(id), dc.setup.abs_anchor_sigmas_m.erase(id);
  for (bool fuse : {true, false}) {
    EstimatorOptions opt = test::testOptions();
    opt.uwb.fuse_calibrated_anchor_pairs = fuse;
    EstimatorNode node(opt, dc.setup);
    bool sent = false;
    for (const auto& in : inputs) {
      if (!sent && node.initialized()) {
        for (SensorId id : {106, 107}) {
          AnchorInit a;
          a.t = inputTime(in);
          a.id = id;
          a.p_AinG = ds.setup.abs_anchor_positions.at(id);
          a.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.01;
          node.onAnchorInit(a);
        }
        sent = true;
      }
      node.onInput(in);
    }
    EXPECT_EQ(node.diagnostics().get("range_calibrated_anchor_pair_skipped") > 0, !fuse);
  }
}
