// DAH joint sets (issue 10, FactorizedCovariance::joinSet): a DAH update naming a member stacks the
// whole set, so the correlations among the members are exact. On a small noise-free flight whose
// every update names a member, DAH with the set equals the centralized EKF (state and the whole
// covariance, including the anchor–anchor cross-covariances that plain DAH never builds); the sets
// merge, forget removed members and are snapshot with the filter; DP ignores them; the node puts
// anchors added together into one set with the tags' γ, the IMU and its baro bias. An update whose
// stack holds every partner of a member leaves that member no pending factor; the bound
// (boundJointSetAnchors, uwb.dah_joint_max_anchors) lets the most refined anchors leave. Every DAH
// update (scalar and vector, with and without sets, members open or closed) follows DAH's rule on
// the dense covariance.
#include <gtest/gtest.h>

#include "estimator/testing/estimator_node_testing.h"
#include "estimator/filter/centralized_ekf.h"
#include "estimator/filter/dense_ekf_update.h"
#include "estimator/filter/joint_set_bound.h"
#include "estimator/filter/modular_filter.h"
#include "estimator/node/estimator_node.h"
#include "estimator/testing/synthetic_scenario.h"
#include "modular_test_helpers.h"
#include "node_test_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

ImuPropagator propagator() { return ImuPropagator(9.81, ImuNoiseOptions{}); }

const std::map<SensorId, Eigen::Vector3d> kTruth = {
    {106, {-1.7, 0.9, 3.2}}, {107, {-2.0, 1.8, 1.7}}, {108, {2.6, -0.2, 0.2}}};

/// IMU (id `imu_id`) and anchors 106–108, each 0.1–0.2 m off its truth with a matching prior
/// (uncorrelated).
template <typename F>
void setUp(F& f, SensorId imu_id = 1) {
  ImuState x;
  x.p_IinG = {0.5, -0.2, 1.5};
  ImuMatrix P = ImuMatrix::Identity() * 0.01;
  P.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) *= 0.1;
  f.reset(imu_id, x, P, Timestamp{});
  int k = 0;
  for (const auto& [id, p] : kTruth) {
    const Eigen::Vector3d off(0.1 + 0.05 * k, -0.1, 0.08);
    f.template addInstance<AnchorKind>(id, AnchorState{p + off}, Eigen::Matrix3d::Identity() * 0.04);
    ++k;
  }
}

/// 0.6 s of hovering with a tag range every 20 ms, the anchors in turn, and (if asked) an
/// anchor–anchor range every 100 ms.
void fly(FusionStrategy& f, bool anchor_pairs) {
  const Eigen::Vector3d acc(0.0, 0.0, 9.81), gyro = Eigen::Vector3d::Zero(), p_true(0.5, -0.2, 1.5);
  const std::vector<SensorId> ids = {106, 107, 108};
  for (int k = 1; k <= 30; ++k) {
    f.propagate(acc, gyro, Timestamp::fromSec(0.02 * k));
    const SensorId a = ids[static_cast<size_t>(k % 3)];
    ASSERT_TRUE(f.update(test::imuAnchorRange(f.state(), a, (kTruth.at(a) - p_true).norm()), 0.0).accepted);
    if (anchor_pairs && k % 5 == 0) {
      const SensorId b = 107 + k % 2;
      ASSERT_TRUE(f.update(test::anchorPairRange(f.state(), 106, b, (kTruth.at(b) - kTruth.at(106)).norm()), 0.0).accepted);
    }
  }
}

std::unique_ptr<CentralizedEkf> centralizedFlight(bool anchor_pairs) {
  auto f = std::make_unique<CentralizedEkf>(propagator(), KindRandomWalks{}, true);
  setUp(*f);
  fly(*f, anchor_pairs);
  return f;
}

/// DAH with the joint set `set` (empty: none) over the same flight.
std::unique_ptr<ModularFilter> dahFlight(const std::vector<SensorId>& set, bool anchor_pairs) {
  auto f = std::make_unique<ModularFilter>(ModularFilter::Mode::DAH, propagator(), KindRandomWalks{}, true);
  setUp(*f);
  if (!set.empty()) f->joinJointSet(set);
  fly(*f, anchor_pairs);
  return f;
}

double maxRelative(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

double maxAnchorDifference(const FusionStrategy& a, const FusionStrategy& b) {
  double d = (a.state().imu.p_IinG - b.state().imu.p_IinG).cwiseAbs().maxCoeff();
  for (const auto& [id, v] : a.state().values<AnchorKind>())
    d = std::max(d, (v.p_AinG - b.state().values<AnchorKind>().at(id).p_AinG).cwiseAbs().maxCoeff());
  return d;
}

/// Feeds `ds` to `node` with one batch of calibrated anchors `ids` at t = 8 s (prior σ² 0.01 m²
/// per axis, or 0.01 × (id − 200) when `growing_priors`). False when the batch was never sent.
bool flyWithAnchorBatch(EstimatorNode& node, const Dataset& ds, const std::vector<SensorId>& ids, bool growing_priors) {
  bool sent = false;
  for (const auto& in : mergeInTimeOrder(ds)) {
    if (!sent && node.initialized() && inputTime(in).sec() >= 8.0) {
      for (SensorId id : ids) {
        AnchorInit a;
        a.id = id;
        a.t = inputTime(in);
        a.p_AinG = Eigen::Vector3d(1.0, 0.5 * id - 100.0, 1.0);
        a.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.01 * (growing_priors ? id - 200 : 1);
        node.onAnchorInit(a);
      }
      sent = true;
    }
    node.onInput(in);
  }
  return sent;
}

/// DAH's rule on the dense covariance `S` (docs/modular_estimator.md, "Strategies"): the exact
/// EKF update (Joseph form) of the participants P (the named instances and their joint sets),
/// Σ_ik' = Σ_ii' Σ_ii⁻¹ Σ_ik for i ∈ P and k ∉ P, every other block unchanged.
Eigen::MatrixXd denseDahUpdate(const Eigen::MatrixXd& S, const FactorizedCovariance& cov, const Linearization& lin) {
  std::vector<SensorId> P;
  for (const JacobianBlock& jb : lin.blocks) {
    P.push_back(jb.id);
    for (SensorId m : cov.jointSet(jb.id)) P.push_back(m);
  }
  StateLayout sub;
  std::vector<int> idx;
  for (const StateBlock& b : cov.layout().blocks()) {
    if (std::find(P.begin(), P.end(), b.id) == P.end()) continue;
    sub.add(b.id, b.kind, b.dim);
    for (int r = 0; r < b.dim; ++r) idx.push_back(b.offset + r);
  }
  Eigen::MatrixXd Spp = S(idx, idx);
  EXPECT_TRUE(denseEkfUpdate(Spp, sub, lin, 0.0, true).accepted);
  Eigen::MatrixXd out = S;
  out(idx, idx) = Spp;
  for (const StateBlock& i : cov.layout().blocks()) {
    if (!sub.find(i.id)) continue;
    const StateBlock& is = sub.at(i.id);
    const Eigen::MatrixXd M = Spp.block(is.offset, is.offset, i.dim, i.dim) *
                              S.block(i.offset, i.offset, i.dim, i.dim).inverse();
    for (const StateBlock& k : cov.layout().blocks()) {
      if (sub.find(k.id)) continue;
      out.block(i.offset, k.offset, i.dim, k.dim) = M * S.block(i.offset, k.offset, i.dim, k.dim);
      out.block(k.offset, i.offset, k.dim, i.dim) = out.block(i.offset, k.offset, i.dim, k.dim).transpose();
    }
  }
  return out;
}

/// A ZUPT-like vector update of the IMU's velocity (3 rows).
Linearization imuVelocityZero(const NominalState& x) {
  Linearization lin;
  lin.residual = -x.imu.v_IinG;
  lin.R = Eigen::Matrix3d::Identity() * 1e-4;
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(3, ImuErr::kDim);
  H.middleCols<3>(ImuErr::kV).setIdentity();
  lin.blocks.push_back({x.imu_id, H});
  return lin;
}

}  // namespace

TEST(DahJointSets, EveryUpdateFollowsDahsRuleOnTheDenseCovariance) {
  // 108 stays outside the set {IMU, 106, 107}: once it is correlated, the members' updates without
  // it are open (DAH's correction folded into L_i, pair factors relative to L_i'⁻¹), a range to 108
  // stacks everything (closed members). Checked after every step against the dense rule. The IMU
  // as id 300 is the larger id of its pairs: its S̄ is its L⁻¹ (remembered as L_inv, read as the
  // identity), which every propagation must invalidate.
  for (const auto& [with_set, imu] : std::vector<std::pair<bool, SensorId>>{{true, 1}, {false, 1}, {true, 300}, {false, 300}}) {
    ModularFilter f(ModularFilter::Mode::DAH, propagator(), KindRandomWalks{}, true);
    setUp(f, imu);
    if (with_set) f.joinJointSet({imu, 106, 107});
    int identity_reads = 0;  // factors that are their instance's remembered L⁻¹, summed over the updates
    const Eigen::Vector3d acc(0.05, 0.0, 9.81), gyro(0.0, 0.01, 0.02), p_true(0.5, -0.2, 1.5);
    int open_updates = 0;
    for (int k = 1; k <= 40; ++k) {
      // Propagation: Σ ← T Σ Tᵀ + Q on the IMU's rows and columns (T = Φ there, I elsewhere).
      ImuState x = f.state().imu;
      ImuMatrix Phi, Q;
      propagator().propagate(x, acc, gyro, 0.02, &Phi, &Q);
      const StateBlock& ib = f.instances().layout().at(imu);
      Eigen::MatrixXd T = Eigen::MatrixXd::Identity(f.layout().dim(), f.layout().dim());
      T.block(ib.offset, ib.offset, ib.dim, ib.dim) = Phi;
      Eigen::MatrixXd propagated = T * f.fullCovariance() * T.transpose();
      propagated.block(ib.offset, ib.offset, ib.dim, ib.dim) += Q;
      f.propagate(acc, gyro, Timestamp::fromSec(0.02 * k));
      EXPECT_LT(maxRelative(f.fullCovariance(), propagated), 1e-9) << "propagation " << k << ", IMU " << imu;
      std::vector<Linearization> updates;
      const SensorId a = 106 + k % 3;
      updates.push_back(test::imuAnchorRange(f.state(), a, (kTruth.at(a) - p_true).norm() + 0.01));
      if (k % 4 == 0) updates.push_back(test::anchorPairRange(f.state(), 106 + k % 2, 108, 3.0));
      if (k % 7 == 0) updates.push_back(imuVelocityZero(f.state()));
      for (const Linearization& lin : updates) {
        const Eigen::MatrixXd expected = denseDahUpdate(f.fullCovariance(), f.instances(), lin);
        ASSERT_TRUE(f.update(lin, 0.0).accepted);
        EXPECT_LT(maxRelative(f.fullCovariance(), expected), 1e-9) << "step " << k << ", set " << with_set << ", IMU " << imu;
        open_updates += f.instances().belief(imu).L.size() > 0 && with_set;
        for (const StateBlock& b : f.instances().layout().blocks()) {
          const InstanceBelief& belief = f.instances().belief(b.id);
          for (const FactorEntry& e : belief.factors->entries()) identity_reads += belief.L_inv && e.S_bar == belief.L_inv;
        }
      }
    }
    if (with_set) {
      EXPECT_GT(open_updates, 10) << "the IMU must have been an open member";
    }
    EXPECT_GT(identity_reads, 10);
    f.checkInvariants();
  }
}

TEST(DahJointSets, AnchorSetWithTagRangesEqualsCentralized) {
  const auto ref = centralizedFlight(false);
  const auto dah = dahFlight({106, 107, 108}, false);
  // Every tag range names the IMU and one member: DAH stacks all instances, the exact update.
  EXPECT_LT(maxRelative(dah->fullCovariance(), ref->fullCovariance()), 1e-9);
  EXPECT_LT(maxAnchorDifference(*dah, *ref), 1e-12);
  // The anchors' cross-covariance built through the pose is there, as in the centralized filter…
  const Eigen::MatrixXd C_ref = ref->covariance(106, 107);
  EXPECT_GT(C_ref.cwiseAbs().maxCoeff(), 1e-4);
  EXPECT_LT(maxRelative(dah->covariance(106, 107), C_ref), 1e-9);
  // … and plain DAH never builds it.
  const auto plain = dahFlight({}, false);
  EXPECT_EQ(plain->covariance(106, 107).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT(maxAnchorDifference(*plain, *ref), 1e-4);
  dah->checkInvariants();
}

TEST(DahJointSets, SetWithTheImuKeepsAnchorPairUpdatesExact) {
  const auto ref = centralizedFlight(true);
  // Anchor–anchor ranges name no IMU: with the anchors alone in the set the IMU's pairs are
  // approximated (DAH's correction), with the IMU in the set the update is exact again.
  const auto anchors_only = dahFlight({106, 107, 108}, true);
  EXPECT_GT(maxRelative(anchors_only->fullCovariance(), ref->fullCovariance()), 1e-6);
  const auto with_imu = dahFlight({106, 107, 108, 1}, true);
  EXPECT_LT(maxRelative(with_imu->fullCovariance(), ref->fullCovariance()), 1e-9);
  EXPECT_LT(maxAnchorDifference(*with_imu, *ref), 1e-12);
  with_imu->checkInvariants();
}

TEST(DahJointSets, AnUpdateCoveringEveryPartnerLeavesNoPendingFactor) {
  // Every instance is in the set: each update's stack holds every partner of every member, so
  // no DAH correction is left to fold (L_i = I), and the result is still the exact one.
  const auto ref = centralizedFlight(true);
  const auto all = dahFlight({106, 107, 108, 1}, true);
  for (SensorId id : {1, 106, 107, 108}) EXPECT_EQ(all->instances().belief(id).L.size(), 0) << id;
  EXPECT_LT(maxRelative(all->fullCovariance(), ref->fullCovariance()), 1e-9);
  // 108 outside: its pairs with the members are approximated, so the members keep a factor.
  const auto part = dahFlight({106, 107, 1}, false);
  EXPECT_GT(part->instances().belief(1).L.size(), 0);
  part->checkInvariants();
}

TEST(DahJointSets, BoundLetsTheMostRefinedAnchorsLeave) {
  auto f = dahFlight({106, 107, 108, 1}, false);
  std::vector<std::pair<double, SensorId>> trace;
  for (SensorId id : {106, 107, 108}) trace.emplace_back(f->covariance(id, id).trace(), id);
  std::sort(trace.begin(), trace.end());
  ASSERT_LT(trace[0].first, trace[2].first);
  // A new anchor with a loose prior joins; at most two anchors may stay: the new one and the
  // least refined of the others.
  f->addInstance<AnchorKind>(109, AnchorState{Eigen::Vector3d(1.0, 2.0, 3.0)}, Eigen::Matrix3d::Identity() * 0.09);
  f->joinJointSet({109, 1});
  EXPECT_EQ(boundJointSetAnchors(*f, 109, 0), 0);  // 0: no bound
  EXPECT_EQ(f->jointSetOf(1).size(), 5u);
  const Eigen::MatrixXd C_before = f->covariance(trace[0].second, 1);
  EXPECT_EQ(boundJointSetAnchors(*f, 109, 2), 2);
  EXPECT_EQ(f->jointSetOf(1), (std::vector<SensorId>{1, trace[2].second, 109}));
  EXPECT_TRUE(f->jointSetOf(trace[0].second).empty());
  // The anchors that left keep their correlations (DAH's from now on), and ranges to them work.
  EXPECT_EQ(f->covariance(trace[0].second, 1), C_before);
  EXPECT_GT(C_before.cwiseAbs().maxCoeff(), 1e-6);
  ASSERT_TRUE(f->update(test::imuAnchorRange(f->state(), trace[0].second,
                                             (kTruth.at(trace[0].second) - Eigen::Vector3d(0.5, -0.2, 1.5)).norm()),
                        0.0)
                  .accepted);
  EXPECT_EQ(boundJointSetAnchors(*f, 109, 2), 0);  // already within the bound
  f->checkInvariants();
}

TEST(DahJointSets, SetsMergeForgetRemovedMembersAndAreSnapshotWithTheFilter) {
  ModularFilter f(ModularFilter::Mode::DAH, propagator(), KindRandomWalks{}, true);
  setUp(f);
  const auto before = f.clone();
  f.joinJointSet({106, 999});  // 999 has no instance: ignored, and a set of one is no set
  EXPECT_TRUE(f.instances().jointSet(106).empty());
  f.joinJointSet({107, 106});
  f.joinJointSet({108, 107});  // overlaps the first: one set
  EXPECT_EQ(f.instances().jointSet(106), (std::vector<SensorId>{106, 107, 108}));
  EXPECT_EQ(f.instances().jointSet(1), std::vector<SensorId>{});
  EXPECT_TRUE(static_cast<const ModularFilter&>(*before).instances().jointSet(106).empty());
  const auto with_set = f.clone();
  ASSERT_TRUE(f.removeInstance(107));
  EXPECT_EQ(f.instances().jointSet(108), (std::vector<SensorId>{106, 108}));
  EXPECT_EQ(static_cast<const ModularFilter&>(*with_set).instances().jointSet(108).size(), 3u);
  ASSERT_TRUE(f.removeInstance(108));
  EXPECT_TRUE(f.instances().jointSet(106).empty());
  // DP updates the whole state anyway: the call is a no-op, the results are unchanged.
  ModularFilter dp(ModularFilter::Mode::DP, propagator(), KindRandomWalks{}, true);
  setUp(dp);
  dp.joinJointSet({106, 107, 108, 1});
  EXPECT_TRUE(dp.instances().jointSet(106).empty());
}

TEST(DahJointSets, NodePutsAnchorsAddedTogetherIntoOneSetWithTheImu) {
  synthetic::SyntheticOptions so;
  so.duration_s = 12.0;
  so.seed = 2;
  const Dataset ds = synthetic::makeSyntheticDataset(so);
  for (const std::string mode : {"batch", "none"}) {
    EstimatorOptions o = test::testOptions();
    o.strategy = "dah";
    o.uwb.dah_joint_anchors = mode;
    EstimatorNode node(o, ds.setup);
    ASSERT_TRUE(flyWithAnchorBatch(node, ds, {201, 202}, false)) << mode;  // two calibrated anchors in one batch
    const auto* f = dynamic_cast<const ModularFilter*>(node.filter());
    ASSERT_NE(f, nullptr);
    const std::vector<SensorId> set = f->instances().jointSet(201);
    if (mode == "none") {
      EXPECT_TRUE(set.empty());
      continue;
    }
    const SensorId imu = f->state().imu_id;
    EXPECT_NE(std::find(set.begin(), set.end(), 202), set.end());
    EXPECT_NE(std::find(set.begin(), set.end(), imu), set.end()) << "uwb.dah_joint_imu";
    // With the IMU its baro bias and the UWB clock's offset, else every member of the set keeps a
    // pair outside it.
    EXPECT_NE(std::find(set.begin(), set.end(), ds.setup.baro_id), set.end()) << "uwb.dah_joint_imu";
    EXPECT_NE(std::find(set.begin(), set.end(), ds.setup.uwb_clock_id), set.end()) << "uwb.dah_joint_imu";
    EXPECT_EQ(set.size(), 5u);  // the synthetic setup has no tag γ states (uwb.dah_joint_tag_biases)
    f->checkInvariants();
    // A re-initialization (here the test hook's pose fault) keeps the set together, the clock's offset
    // back at its prior in it.
    EstimatorNodeTesting::injectPoseError(node, Eigen::Vector3d(1.0, 0.0, 0.0), 0.3);
    const auto* g = dynamic_cast<const ModularFilter*>(node.filter());
    ASSERT_NE(g, nullptr);
    std::vector<SensorId> after = g->instances().jointSet(201), before = set;
    std::sort(after.begin(), after.end());
    std::sort(before.begin(), before.end());
    EXPECT_EQ(after, before);
    g->checkInvariants();
  }
}

TEST(DahJointSets, NodeBoundsTheAnchorsOfASet) {
  synthetic::SyntheticOptions so;
  so.duration_s = 10.0;
  so.seed = 2;
  const Dataset ds = synthetic::makeSyntheticDataset(so);
  for (const int max_anchors : {0, 2}) {
    EstimatorOptions o = test::testOptions();
    o.strategy = "dah";
    o.uwb.dah_joint_max_anchors = max_anchors;
    EstimatorNode node(o, ds.setup);
    ASSERT_TRUE(flyWithAnchorBatch(node, ds, {201, 202, 203}, true));  // one batch, the last with the loosest prior
    const std::vector<SensorId> set = node.filter()->jointSetOf(203);
    const auto in_set = [&](SensorId id) { return std::find(set.begin(), set.end(), id) != set.end(); };
    EXPECT_TRUE(in_set(203)) << max_anchors;
    EXPECT_TRUE(in_set(202)) << max_anchors;  // the loosest of the others stays
    EXPECT_EQ(in_set(201), max_anchors == 0) << max_anchors;  // the most refined leaves under the bound
    node.filter()->checkInvariants();
  }
}
