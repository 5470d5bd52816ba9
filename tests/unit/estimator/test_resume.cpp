/// Resume and makeCheckpoint (estimator/restart/resume.h): the checkpoint of a small filter, a
/// checkpoint too old refused, a short outage resumed with p += v·Δt and
/// P ← Φ P Φᵀ + diag((aΔt²/2)², (aΔt)², (ωΔt)²) checked against numbers by hand, a long outage
/// that keeps anchors and the baro reference only, and the kept instances restored with their
/// random walk (a baro bias only against the same reference pressure).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "estimator/filter/strategy_factory.h"
#include "estimator/restart/resume.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

Timestamp at(double s) { return Timestamp::fromSec(s); }

constexpr double kRef = 97000.0;  // baro reference pressure [Pa]

/// Exact anchors 101–104, tag 100, baro 2, height 3 (the SystemSetup defaults).
SystemSetup setup() {
  SystemSetup s;
  s.rel_tag_positions[100] = Eigen::Vector3d::Zero();
  s.abs_anchor_positions = {{101, {5, 0, 3}}, {102, {0, 5, 3}}, {103, {-5, 0, 3}}, {104, {0, -5, 3}}};
  return s;
}

EstimatorOptions options() {
  EstimatorOptions o;
  o.init.resume_max_age_s = 5.0;
  o.init.resume_max_outage_s = 0.5;
  o.init.resume_max_acc_m_s2 = 3.0;
  o.init.resume_max_rate_deg_s = 30.0;
  o.baro.bias_rw_m_per_sqrt_s = 0.02;
  o.height.bias_rw_m_per_sqrt_s = 0.01;
  return o;
}

/// A filter at t = 10 s moving at v = (1, −2, 0.5) m/s with diagonal covariance (p 0.01, v 0.04,
/// θ 0.001, biases 1e-4), a baro bias 0.3 m (σ² 0.04), a height bias −0.1 m (σ² 0.01) and an
/// estimated anchor 106.
std::unique_ptr<FusionStrategy> smallFilter(const EstimatorOptions& o) {
  auto f = makeStrategy(o);
  ImuState x;
  x.p_IinG = {1.0, 2.0, 3.0};
  x.v_IinG = {1.0, -2.0, 0.5};
  x.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  ImuMatrix P = ImuMatrix::Identity() * 1e-4;
  P.block<3, 3>(ImuErr::kP, ImuErr::kP) = Eigen::Matrix3d::Identity() * 0.01;
  P.block<3, 3>(ImuErr::kV, ImuErr::kV) = Eigen::Matrix3d::Identity() * 0.04;
  P.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) = Eigen::Matrix3d::Identity() * 0.001;
  f->reset(1, x, P, at(10.0));
  f->addInstance<BaroBiasKind>(2, 0.3, Eigen::MatrixXd::Constant(1, 1, 0.04));
  f->addInstance<HeightBiasKind>(3, -0.1, Eigen::MatrixXd::Constant(1, 1, 0.01));
  f->addInstance<AnchorKind>(106, AnchorState(Eigen::Vector3d(4, 4, 0.5)), Eigen::Matrix3d::Identity() * 0.09);
  return f;
}

struct ResumeTest : ::testing::Test {
  EstimatorOptions o = options();
  SystemSetup s = setup();
  UwbNetwork network{s, 0.15};
  Diagnostics diag;
  std::unique_ptr<FusionStrategy> f = smallFilter(o);
  EstimatorCheckpoint checkpoint() const { return makeCheckpoint(*f, network, true, kRef, o); }
  static ImuSample imuAt(double t) { return {at(t), {0.1, 0.2, 9.8}, {0.01, 0.0, 0.0}}; }
};

}  // namespace

TEST_F(ResumeTest, TheCheckpointHoldsTheImuBlockKeptInstancesAndAnchors) {
  const EstimatorCheckpoint c = checkpoint();
  EXPECT_EQ(c.t, at(10.0));
  EXPECT_EQ(c.imu_id, 1);
  EXPECT_EQ(c.imu.p_IinG, f->state().imu.p_IinG);
  EXPECT_EQ(c.imu.v_IinG, f->state().imu.v_IinG);
  EXPECT_TRUE(c.cov_imu.isApprox(f->covariance(1, 1), 1e-15));
  EXPECT_TRUE(c.landed);
  EXPECT_EQ(c.baro_reference_pa, kRef);
  ASSERT_EQ(c.instances.size(), 2u);  // baro and height: kept; the anchor is a calibration
  const InstanceRecord* baro = c.find("baro", 2);
  const InstanceRecord* height = c.find("height", 3);
  ASSERT_TRUE(baro && height);
  EXPECT_DOUBLE_EQ(baro->value(0), 0.3);
  EXPECT_DOUBLE_EQ(baro->cov(0, 0), 0.04);
  EXPECT_DOUBLE_EQ(height->value(0), -0.1);
  EXPECT_DOUBLE_EQ(height->cov(0, 0), 0.01);
  ASSERT_EQ(c.anchors.size(), 1u);
  EXPECT_EQ(c.anchors[0].id, 106);
  EXPECT_EQ(c.anchors[0].p_AinG, Eigen::Vector3d(4, 4, 0.5));
  EXPECT_TRUE(c.anchors[0].cov_p_m2.isApprox(Eigen::Matrix3d::Identity() * 0.09, 1e-15));
  // With the baro off, its bias is no kept instance.
  EstimatorOptions no_baro = o;
  no_baro.baro.enabled = false;
  const EstimatorCheckpoint c2 = makeCheckpoint(*f, network, false, std::nullopt, no_baro);
  EXPECT_EQ(c2.find("baro", 2), nullptr);
  EXPECT_NE(c2.find("height", 3), nullptr);
  // Without the anchors (a checkpoint whose anchors' file stays): the rest as with them.
  const EstimatorCheckpoint c3 = makeCheckpoint(*f, network, true, kRef, o, /*with_anchors=*/false);
  EXPECT_TRUE(c3.anchors.empty());
  EXPECT_EQ(c3.t, c.t);
  EXPECT_EQ(c3.instances.size(), c.instances.size());
  EXPECT_TRUE(c3.cov_imu.isApprox(c.cov_imu, 0.0));
}

TEST_F(ResumeTest, ACheckpointOlderThanTheMaxAgeIsRefused) {
  for (const double t : {15.001, 9.9}) {  // 5.001 s old, or newer than the first IMU sample
    Diagnostics d;
    Resume r(o, s, d);
    r.offer(checkpoint());
    ASSERT_TRUE(r.offered());
    std::vector<AnchorInit> anchors;
    EXPECT_FALSE(r.at(imuAt(t), anchors)) << t;
    EXPECT_FALSE(r.offered());
    EXPECT_EQ(d.get("resume_refused"), 1);
    EXPECT_EQ(d.get("resumed"), 0);
    EXPECT_TRUE(anchors.empty());
    EXPECT_FALSE(r.keptBaroReference());
  }
}

TEST_F(ResumeTest, AShortOutageResumesThePoseWithTheGrownCovariance) {
  Resume r(o, s, diag);
  r.offer(checkpoint());
  std::vector<AnchorInit> anchors;
  const auto b = r.at(imuAt(10.4), anchors);  // Δt = 0.4 s
  ASSERT_TRUE(b);
  EXPECT_EQ(diag.get("resumed"), 1);
  EXPECT_TRUE(b->from_checkpoint);
  EXPECT_EQ(b->t, at(10.4));
  EXPECT_EQ(b->last_imu.t, at(10.4));
  EXPECT_TRUE(b->landed);
  EXPECT_EQ(b->baro_reference_pa, kRef);
  EXPECT_TRUE(b->imu.p_IinG.isApprox(Eigen::Vector3d(1.4, 1.2, 3.2), 1e-12));  // p + v·0.4
  EXPECT_EQ(b->imu.v_IinG, f->state().imu.v_IinG);
  EXPECT_TRUE(b->imu.q_ItoG.isApprox(f->state().imu.q_ItoG, 1e-15));
  // Φ P Φᵀ with Φ_pv = 0.4 I: pp 0.01 + 0.16·0.04 = 0.0164, pv 0.4·0.04 = 0.016, vv 0.04; plus
  // (3·0.4²/2)² = 0.0576 on p, (3·0.4)² = 1.44 on v, (π/6·0.4)² on θ.
  const double w = M_PI / 6.0 * 0.4;
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(b->cov(ImuErr::kP + i, ImuErr::kP + i), 0.074, 1e-12);
    EXPECT_NEAR(b->cov(ImuErr::kP + i, ImuErr::kV + i), 0.016, 1e-12);
    EXPECT_NEAR(b->cov(ImuErr::kV + i, ImuErr::kP + i), 0.016, 1e-12);
    EXPECT_NEAR(b->cov(ImuErr::kV + i, ImuErr::kV + i), 1.48, 1e-12);
    EXPECT_NEAR(b->cov(ImuErr::kTheta + i, ImuErr::kTheta + i), 0.001 + w * w, 1e-12);
    EXPECT_NEAR(b->cov(ImuErr::kBg + i, ImuErr::kBg + i), 1e-4, 1e-15);  // biases: unchanged
    EXPECT_NEAR(b->cov(ImuErr::kBa + i, ImuErr::kBa + i), 1e-4, 1e-15);
  }
  EXPECT_NEAR(b->cov(ImuErr::kP, ImuErr::kV + 1), 0.0, 1e-15);  // no coupling across axes
  EXPECT_NEAR(b->cov(ImuErr::kP, ImuErr::kTheta), 0.0, 1e-15);
  ASSERT_EQ(anchors.size(), 1u);
  EXPECT_EQ(anchors[0].id, 106);
  EXPECT_EQ(r.keptBaroReference(), kRef);
}

TEST_F(ResumeTest, ALongOutageKeepsAnchorsAndTheBaroReferenceOnly) {
  Resume r(o, s, diag);
  r.offer(checkpoint());
  std::vector<AnchorInit> anchors;
  EXPECT_FALSE(r.at(imuAt(10.501), anchors));  // just beyond resume_max_outage_s
  EXPECT_EQ(diag.get("resume_refused"), 0);
  EXPECT_EQ(diag.get("resumed"), 1);
  ASSERT_EQ(anchors.size(), 1u);
  EXPECT_EQ(anchors[0].id, 106);
  EXPECT_EQ(anchors[0].p_AinG, Eigen::Vector3d(4, 4, 0.5));
  EXPECT_EQ(r.keptBaroReference(), kRef);
}

TEST_F(ResumeTest, KeptInstancesComeBackWithTheirRandomWalk) {
  Resume r(o, s, diag);
  r.offer(checkpoint());
  std::vector<AnchorInit> anchors;
  ASSERT_FALSE(r.at(imuAt(12.0), anchors));
  auto g = makeStrategy(o);  // the new filter, initialized anew at 12 s
  g->reset(1, ImuState{}, ImuMatrix::Identity(), at(12.0));
  g->addInstance<HeightBiasKind>(3, 0.0, Eigen::MatrixXd::Constant(1, 1, 0.09));  // its prior, replaced
  r.restoreKept(*g, at(12.0), kRef);
  const auto& baro = g->state().values<BaroBiasKind>();
  const auto& height = g->state().values<HeightBiasKind>();
  ASSERT_EQ(baro.count(2), 1u);
  ASSERT_EQ(height.count(3), 1u);
  EXPECT_DOUBLE_EQ(baro.at(2), 0.3);
  EXPECT_DOUBLE_EQ(height.at(3), -0.1);
  // Δt = 2 s: 0.04 + 0.02²·2 and 0.01 + 0.01²·2.
  EXPECT_NEAR(g->covariance(2, 2)(0, 0), 0.0408, 1e-12);
  EXPECT_NEAR(g->covariance(3, 3)(0, 0), 0.0102, 1e-12);
  EXPECT_EQ(diag.get("resumed_instances"), 2);
  // Then forgotten: a second call adds nothing, the reference is no longer held.
  EXPECT_FALSE(r.keptBaroReference());
  auto h = makeStrategy(o);
  h->reset(1, ImuState{}, ImuMatrix::Identity(), at(12.0));
  r.restoreKept(*h, at(12.0), kRef);
  EXPECT_TRUE(h->state().values<BaroBiasKind>().empty());
  EXPECT_EQ(diag.get("resumed_instances"), 2);
}

TEST_F(ResumeTest, ABaroBiasIsNotRestoredAgainstAnotherReference) {
  for (const std::optional<double> other : {std::optional<double>(98000.0), std::optional<double>()}) {
    Diagnostics d;
    Resume r(o, s, d);
    r.offer(checkpoint());
    std::vector<AnchorInit> anchors;
    ASSERT_TRUE(r.at(imuAt(10.2), anchors));
    auto g = makeStrategy(o);
    g->reset(1, ImuState{}, ImuMatrix::Identity(), at(10.2));
    r.restoreKept(*g, at(10.2), other);
    EXPECT_TRUE(g->state().values<BaroBiasKind>().empty());
    ASSERT_EQ(g->state().values<HeightBiasKind>().count(3), 1u);
    EXPECT_NEAR(g->covariance(3, 3)(0, 0), 0.01 + 1e-4 * 0.2, 1e-12);
    EXPECT_EQ(d.get("resumed_instances"), 1);
  }
}
