// DAH joint sets (issue 10, FactorizedCovariance::joinSet): a DAH update naming a member stacks the
// whole set, so the correlations among the members are exact. On a small noise-free flight whose
// every update names a member, DAH with the set equals the centralized EKF (state and the whole
// covariance, including the anchor–anchor cross-covariances that plain DAH never builds); the sets
// merge, forget removed members and are snapshot with the filter; DP ignores them; the node puts
// anchors added together into one set with the tags' γ and the IMU.
#include <gtest/gtest.h>

#include "estimator/filter/centralized_ekf.h"
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

/// IMU and anchors 106–108, each 0.1–0.2 m off its truth with a matching prior (uncorrelated).
template <typename F>
void setUp(F& f) {
  ImuState x;
  x.p_IinG = {0.5, -0.2, 1.5};
  ImuMatrix P = ImuMatrix::Identity() * 0.01;
  P.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) *= 0.1;
  f.reset(1, x, P, Timestamp{});
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

}  // namespace

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
    bool sent = false;
    for (const auto& in : mergeInTimeOrder(ds)) {
      if (!sent && node.initialized() && inputTime(in).sec() >= 8.0) {
        for (SensorId id : {201, 202}) {  // two calibrated anchors in one batch
          AnchorInit a;
          a.id = id;
          a.t = inputTime(in);
          a.p_AinG = Eigen::Vector3d(1.0, 0.5 * id - 100.0, 1.0);
          a.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.01;
          node.onAnchorInit(a);
        }
        sent = true;
      }
      node.onInput(in);
    }
    ASSERT_TRUE(sent) << mode;
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
    EXPECT_EQ(set.size(), 3u);  // the synthetic setup has no tag γ states (uwb.dah_joint_tag_biases)
    f->checkInvariants();
    // A re-initialization (here the test hook's pose fault) keeps the set together.
    node.injectPoseError(Eigen::Vector3d(1.0, 0.0, 0.0), 0.3);
    const auto* g = dynamic_cast<const ModularFilter*>(node.filter());
    ASSERT_NE(g, nullptr);
    std::vector<SensorId> after = g->instances().jointSet(201), before = set;
    std::sort(after.begin(), after.end());
    std::sort(before.begin(), before.end());
    EXPECT_EQ(after, before);
    g->checkInvariants();
  }
}
