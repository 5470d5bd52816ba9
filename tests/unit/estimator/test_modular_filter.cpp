/// ModularFilter / FactorizedCovariance: the storage rule (smaller id stores Σ_ij, the other the
/// identity), isolated propagation and private updates (only the owner's block changes),
/// copy-on-write snapshots, DAH updates touching only the participants, removal.
#include <gtest/gtest.h>

#include "estimator/filter/centralized_ekf.h"
#include "estimator/filter/modular_filter.h"
#include "estimator/zupt/zupt_model.h"
#include "modular_test_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

ImuPropagator propagator() { return ImuPropagator(9.81, ImuNoiseOptions{}); }

/// IMU, baro 2, anchors 106, 107 (all uncorrelated).
template <typename F>
void setUp(F& f) {
  ImuState x;
  x.p_IinG = {0.5, -0.2, 1.5};
  x.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  ImuMatrix P = ImuMatrix::Identity() * 0.01;
  P.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) *= 0.1;
  f.reset(1, x, P, Timestamp{});
  f.template addInstance<BaroBiasKind>(2, 0.1, Eigen::MatrixXd::Constant(1, 1, 0.25));
  f.template addInstance<AnchorKind>(106, AnchorState{Eigen::Vector3d(-1.772, 0.943, 3.256)}, Eigen::Matrix3d::Identity() * 0.04);
  f.template addInstance<AnchorKind>(107, AnchorState{Eigen::Vector3d(-2.021, 1.814, 1.732)}, Eigen::Matrix3d::Identity() * 0.09);
}

const Eigen::Vector3d kAcc(0.1, -0.2, 9.9), kGyro(0.02, -0.01, 0.1);

}  // namespace

TEST(ModularFilter, SmallerIdStoresTheCrossCovarianceTheOtherTheIdentity) {
  ModularFilter f(ModularFilter::Mode::DP, propagator(), KindRandomWalks{}.set<BaroBiasKind>(0.02), true);
  setUp(f);
  f.propagate(kAcc, kGyro, Timestamp::fromSec(0.005));
  ASSERT_TRUE(f.update(test::imuAnchorRange(f.state(), 106, 4.0), 0.0).accepted);
  const auto& cov = f.instances();
  // DP writes every correlated pair: IMU (id 1) holds Σ_1,106 (15×3), anchor 106 the identity.
  const FactorEntry* e1 = cov.belief(1).factors->find(106);
  const FactorEntry* e106 = cov.belief(106).factors->find(1);
  ASSERT_TRUE(e1 && e106);
  ASSERT_TRUE(e1->S_bar);
  EXPECT_EQ(e1->S_bar->rows(), 15);
  EXPECT_EQ(e1->S_bar->cols(), 3);
  EXPECT_FALSE(e106->S_bar) << "the larger id stores the identity (null)";
  EXPECT_EQ(cov.belief(1).L.size(), 0) << "DP resets the pending factor";
  EXPECT_LT((*e1->S_bar - f.covariance(1, 106)).cwiseAbs().maxCoeff(), 1e-15);
  // Anchor 107 was uncorrelated with everything and the update does not correlate it.
  EXPECT_EQ(cov.belief(107).factors->size(), 0u);
  f.checkInvariants();
}

TEST(ModularFilter, PropagationChangesOnlyTheImuBlockAndItsPendingFactor) {
  for (auto mode : {ModularFilter::Mode::DP, ModularFilter::Mode::DAH}) {
    ModularFilter f(mode, propagator(), KindRandomWalks{}, true);
    setUp(f);
    f.update(test::imuAnchorRange(f.state(), 106, 4.0), 0.0);
    f.update(test::anchorPairRange(f.state(), 106, 107, 1.8), 0.0);
    const auto before = f.clone();
    const auto& cb = static_cast<const ModularFilter&>(*before).instances();
    const Eigen::MatrixXd P0 = f.fullCovariance();
    const Eigen::MatrixXd S1_106 = *f.instances().belief(1).factors->find(106)->S_bar;
    f.propagate(kAcc, kGyro, Timestamp::fromSec(0.005));
    f.propagate(kAcc, kGyro, Timestamp::fromSec(0.010));
    const auto& c = f.instances();
    // Anchors and baro (no random walk here) untouched: the same shared beliefs as the snapshot.
    for (SensorId id : {2, 106, 107}) EXPECT_EQ(c.beliefPtr(id), cb.beliefPtr(id)) << id;
    // The IMU's factor dictionary is shared too: only Σ_II and L_I were copied.
    EXPECT_EQ(c.belief(1).factors, cb.belief(1).factors);
    EXPECT_NE(c.beliefPtr(1), cb.beliefPtr(1));
    EXPECT_EQ(*c.belief(1).factors->find(106)->S_bar, S1_106);
    // The snapshot still holds the old covariance.
    EXPECT_EQ(before->fullCovariance(), P0);
    // And the reconstruction equals the dense propagation Σ_Ij ← Φ Σ_Ij.
    CentralizedEkf ref(propagator(), KindRandomWalks{}, true);
    setUp(ref);
    ref.update(test::imuAnchorRange(ref.state(), 106, 4.0), 0.0);
    ref.update(test::anchorPairRange(ref.state(), 106, 107, 1.8), 0.0);
    if (mode == ModularFilter::Mode::DP) {
      ref.propagate(kAcc, kGyro, Timestamp::fromSec(0.005));
      ref.propagate(kAcc, kGyro, Timestamp::fromSec(0.010));
      EXPECT_LT((ref.fullCovariance() - f.fullCovariance()).cwiseAbs().maxCoeff(), 1e-14);
    }
    f.checkInvariants();
  }
}

TEST(ModularFilter, DahUpdateTouchesOnlyTheParticipants) {
  ModularFilter f(ModularFilter::Mode::DAH, propagator(), KindRandomWalks{}.set<BaroBiasKind>(0.02), true);
  setUp(f);
  f.update(test::imuAnchorRange(f.state(), 106, 4.0), 0.0);
  f.update(test::imuAnchorRange(f.state(), 107, 3.5), 0.0);
  const auto snap = f.clone();
  const auto& cs = static_cast<const ModularFilter&>(*snap).instances();
  const NominalState x0 = f.state();
  // Anchor–anchor range: P = {106, 107}; the IMU and the baro are not touched.
  ASSERT_TRUE(f.update(test::anchorPairRange(f.state(), 106, 107, 1.9), 0.0).accepted);
  EXPECT_EQ(f.instances().beliefPtr(1), cs.beliefPtr(1));
  EXPECT_EQ(f.instances().beliefPtr(2), cs.beliefPtr(2));
  EXPECT_EQ(f.state().imu.p_IinG, x0.imu.p_IinG);
  EXPECT_NE(f.state().values<AnchorKind>().at(106).p_AinG, x0.values<AnchorKind>().at(106).p_AinG);
  // 106 < 107: 106 stores Σ_106,107 relative to its pending factor, 107 its L⁻¹.
  const auto& c = f.instances();
  const InstanceBelief& b106 = c.belief(106);
  const Eigen::MatrixXd S = b106.L.size() ? Eigen::MatrixXd(b106.L * *b106.factors->find(107)->S_bar)
                                          : *b106.factors->find(107)->S_bar;
  EXPECT_LT((S - f.covariance(106, 107)).cwiseAbs().maxCoeff(), 1e-14);
  // Σ_1,106 follows the DAH rule Σ_ik' = Σ_ii' Σ_ii⁻¹ Σ_ik.
  const Eigen::Matrix3d S_old = snap->covariance(106, 106), S_new = f.covariance(106, 106);
  const Eigen::MatrixXd expected = (S_new * S_old.inverse() * snap->covariance(106, 1)).transpose();
  EXPECT_LT((f.covariance(1, 106) - expected).cwiseAbs().maxCoeff(), 1e-12);
  f.checkInvariants();
}

TEST(ModularFilter, PrivateUpdateIsExactForTheCrossCovariancesAndIsolated) {
  ModularFilter dah(ModularFilter::Mode::DAH, propagator(), KindRandomWalks{}.set<BaroBiasKind>(0.02), true);
  CentralizedEkf ref(propagator(), KindRandomWalks{}.set<BaroBiasKind>(0.02), true);
  setUp(dah);
  setUp(ref);
  for (FusionStrategy* f : {static_cast<FusionStrategy*>(&dah), static_cast<FusionStrategy*>(&ref)}) {
    f->update(test::imuAnchorRange(f->state(), 106, 4.0), 0.0);
    f->propagate(kAcc, kGyro, Timestamp::fromSec(0.005));
  }
  const auto snap = dah.clone();
  ZuptModel zupt(Eigen::Vector3d(0, 0, -9.81));
  ZuptMeasurement z;
  z.acc_m_s2 = kAcc;
  z.gyro_rad_s = kGyro;
  ASSERT_TRUE(dah.update(zupt.linearize(z, dah.state()), 0.0).accepted);
  ASSERT_TRUE(ref.update(zupt.linearize(z, ref.state()), 0.0).accepted);
  const auto& cs = static_cast<const ModularFilter&>(*snap).instances();
  for (SensorId id : {2, 106, 107}) EXPECT_EQ(dah.instances().beliefPtr(id), cs.beliefPtr(id)) << id;
  EXPECT_EQ(dah.instances().belief(1).factors, cs.belief(1).factors) << "only L_I changed";
  // Σ_II and Σ_I,106 equal the exact update (the private update corrects the factor exactly).
  EXPECT_LT((dah.covariance(1, 1) - ref.covariance(1, 1)).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((dah.covariance(1, 106) - ref.covariance(1, 106)).cwiseAbs().maxCoeff(), 1e-12);
  dah.checkInvariants();
}

TEST(ModularFilter, RemovingAnInstanceDropsThePartnersFactors) {
  for (auto mode : {ModularFilter::Mode::DP, ModularFilter::Mode::DAH}) {
    ModularFilter f(mode, propagator(), KindRandomWalks{}.set<BaroBiasKind>(0.02), true);
    setUp(f);
    f.update(test::imuAnchorRange(f.state(), 106, 4.0), 0.0);
    f.update(test::anchorPairRange(f.state(), 106, 107, 1.9), 0.0);
    const Eigen::MatrixXd P = f.fullCovariance();
    const auto snap = f.clone();
    ASSERT_TRUE(f.removeInstance(106));
    EXPECT_FALSE(f.removeInstance(106));
    EXPECT_FALSE(f.removeInstance(1)) << "the IMU stays";
    EXPECT_EQ(f.layout().dim(), 15 + 1 + 3);
    EXPECT_FALSE(f.instances().belief(1).factors->find(106));
    EXPECT_FALSE(f.instances().belief(107).factors->find(106));
    EXPECT_EQ(f.state().values<AnchorKind>().count(106), 0u);
    f.checkInvariants();
    EXPECT_EQ(snap->fullCovariance(), P) << "the snapshot keeps the removed instance";
    // Re-adding starts uncorrelated.
    f.addInstance<AnchorKind>(106, AnchorState{Eigen::Vector3d(-1.7, 0.9, 3.2)}, Eigen::Matrix3d::Identity() * 0.04);
    EXPECT_TRUE(f.covariance(1, 106).isZero(0.0));
    f.checkInvariants();
  }
}

TEST(ModularFilter, LazyFactorRenormalizationIsExact) {
  ModularFilter f(ModularFilter::Mode::DAH, propagator(), KindRandomWalks{}.set<BaroBiasKind>(0.02), true);
  setUp(f);
  f.update(test::imuAnchorRange(f.state(), 106, 4.0), 0.0);
  f.update(test::imuAnchorRange(f.state(), 107, 3.5), 0.0);
  for (int k = 1; k <= 50; ++k) f.propagate(kAcc, kGyro, Timestamp::fromSec(0.005 * k));
  ModularFilter g = f;
  const Eigen::MatrixXd P = f.fullCovariance();
  g.renormalize(1);
  EXPECT_EQ(g.instances().belief(1).L.size(), 0);
  EXPECT_LT((g.fullCovariance() - P).cwiseAbs().maxCoeff(), 1e-14 * P.cwiseAbs().maxCoeff());
  EXPECT_EQ(f.fullCovariance(), P) << "the copy's renormalization does not touch the original";
}
