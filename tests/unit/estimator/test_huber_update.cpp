/// The Huber-weighted update (Linearization::huber_k): in every strategy it equals the plain
/// update with R_eff = R + S (√NIS / k − 1), reports the NIS of the stated R, and is the plain
/// update where it must be (within k, above the prior-ratio bound, gated, switched off); the
/// correlated-error factor on R (Linearization::step_noise_factor) weighs the step only.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>

#include "estimator/core/huber.h"
#include "estimator/filter/centralized_ekf.h"
#include "estimator/filter/modular_filter.h"
#include "modular_test_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

std::unique_ptr<FusionStrategy> makeStrategy(const std::string& name, double sigma_imu_p_m) {
  const ImuPropagator prop(9.81, ImuNoiseOptions{});
  std::unique_ptr<FusionStrategy> f;
  if (name == "centralized")
    f = std::make_unique<CentralizedEkf>(prop, KindRandomWalks{}, true);
  else
    f = std::make_unique<ModularFilter>(name == "dp" ? ModularFilter::Mode::DP : ModularFilter::Mode::DAH, prop,
                                        KindRandomWalks{}, true);
  ImuState x;
  x.p_IinG = {0.5, -0.2, 1.5};
  ImuMatrix P = ImuMatrix::Identity() * 1e-4;
  P.block<3, 3>(ImuErr::kP, ImuErr::kP) = Eigen::Matrix3d::Identity() * sigma_imu_p_m * sigma_imu_p_m;
  f->reset(1, x, P, Timestamp{});
  f->addInstance<AnchorKind>(106, AnchorState{Eigen::Vector3d(-1.772, 0.943, 3.256)}, Eigen::Matrix3d::Identity() * 1e-4);
  f->addInstance<AnchorKind>(107, AnchorState{Eigen::Vector3d(-2.021, 1.814, 1.732)}, Eigen::Matrix3d::Identity() * 1e-2);
  // A plain range to 107 correlates it with the IMU: a later IMU–106 update then has a participant
  // with a partner outside it, so DAH folds its correction into the IMU's pending factor.
  const Linearization to107 = test::imuAnchorRange(f->state(), 107, 2.9);
  if (!f->update(to107, 0.0).accepted) throw std::logic_error("the correlating range was not fused");
  return f;
}

/// Largest difference of the IMU–anchor and anchor–anchor covariances of `a` and `b`.
double crossDifference(const FusionStrategy& a, const FusionStrategy& b) {
  double d = 0.0;
  for (auto [i, j] : {std::pair<SensorId, SensorId>{1, 106}, {1, 107}, {106, 107}})
    d = std::max(d, (a.covariance(i, j) - b.covariance(i, j)).cwiseAbs().maxCoeff());
  return d;
}

/// S = H P Hᵀ + R of `lin` in `f` (one range: IMU position and anchor 106).
double innovationVariance(const FusionStrategy& f, const Linearization& lin) {
  double s = lin.R(0, 0);
  for (const auto& a : lin.blocks)
    for (const auto& b : lin.blocks) s += (a.H * f.covariance(a.id, b.id) * b.H.transpose())(0, 0);
  return s;
}

/// Updates `weighted` with `lin` and `plain` with `lin_eff`, the plain update with the R_eff the
/// weighting stands for: both accepted, the same states and cross-covariances. Returns the
/// weighted update's result.
UpdateResult expectThePlainUpdateWithREff(FusionStrategy& weighted, const Linearization& lin, FusionStrategy& plain,
                                          const Linearization& lin_eff) {
  const UpdateResult rw = weighted.update(lin, 0.0), rp = plain.update(lin_eff, 0.0);
  EXPECT_TRUE(rw.accepted && rp.accepted);
  EXPECT_LT(test::relativeDifference(weighted, plain), 1e-12);
  EXPECT_LT(crossDifference(weighted, plain), 1e-15);
  return rw;
}

}  // namespace

TEST(HuberUpdate, InflationIsRootNisOverKBeyondKAndOneElsewhere) {
  EXPECT_DOUBLE_EQ(huber::innovationInflation(9.0, 2.0, 0.5, 1.0), 1.5);
  EXPECT_DOUBLE_EQ(huber::innovationInflation(3.0, 2.0, 0.5, 1.0), 1.0);  // within k = 2
  EXPECT_DOUBLE_EQ(huber::innovationInflation(9.0, 0.0, 0.5, 1.0), 1.0);  // off
  EXPECT_DOUBLE_EQ(huber::innovationInflation(9.0, 2.0, 1.5, 1.0), 1.0);  // the state's error dominates S
  EXPECT_DOUBLE_EQ(huber::innovationInflation(NAN, 2.0, 0.5, 1.0), 1.0);
  EXPECT_DOUBLE_EQ(huber::innovationInflation(9.0, 2.0, NAN, 1.0), 1.0);
  EXPECT_DOUBLE_EQ(huber::innovationInflation(9.0, 2.0, INFINITY, 1.0), 1.0);  // R = 0
  EXPECT_DOUBLE_EQ(huber::innovationInflation(4.0, 2.0, 0.5, 1.0), 1.0);  // NIS = k²: still quadratic
  EXPECT_DOUBLE_EQ(huber::innovationInflation(16.0, 2.0, 1.0, 1.0), 2.0);  // ratio at the bound: weighted
}

TEST(HuberUpdate, EqualsThePlainUpdateWithTheInflatedNoiseInEveryStrategy) {
  for (const std::string name : {"centralized", "dp", "dah"}) {
    SCOPED_TRACE(name);
    auto robust = makeStrategy(name, 0.05);  // H P Hᵀ ≈ 0.0026 against R = 0.01: ratio 0.26
    auto plain = robust->clone();
    const Eigen::Vector3d p0 = robust->state().imu.p_IinG;
    Linearization lin = test::imuAnchorRange(robust->state(), 106, 4.0);
    const double S = innovationVariance(*robust, lin), r = lin.residual(0);
    ASSERT_LT((S - lin.R(0, 0)) / lin.R(0, 0), 1.0);
    const double e = std::abs(r) / std::sqrt(S);
    ASSERT_GT(e, 2.5) << "the test range must be beyond k";
    lin.huber_k = 2.0;
    lin.huber_max_prior_ratio = 1.0;
    Linearization lin_eff = test::imuAnchorRange(plain->state(), 106, 4.0);
    lin_eff.R(0, 0) += S * (e / 2.0 - 1.0);
    const UpdateResult rh = expectThePlainUpdateWithREff(*robust, lin, *plain, lin_eff);
    EXPECT_NEAR(rh.nis, r * r / S, 1e-12) << "the NIS of the stated R";
    // Against the plain update with the stated R, the step δx = P Hᵀ ν / S shrinks by k / e.
    auto stated = makeStrategy(name, 0.05);
    ASSERT_TRUE(stated->update(test::imuAnchorRange(stated->state(), 106, 4.0), 0.0).accepted);
    EXPECT_NEAR((robust->state().imu.p_IinG - p0).norm() / (stated->state().imu.p_IinG - p0).norm(), 2.0 / e, 1e-9);
  }
}

/// A Huber update (k = 2, bound 1) of the range to anchor 106 measured as `z(state)` with the IMU
/// position at σ `sigma_p_m` leaves exactly the state and covariances of the plain update.
/// `beyond_k`: the range is beyond k (so only the prior-ratio bound can keep it plain), else within.
void expectThePlainUpdate(const std::string& name, double sigma_p_m, double (*z)(const FusionStrategy&), bool beyond_k) {
  auto robust = makeStrategy(name, sigma_p_m);
  auto plain = robust->clone();
  Linearization lin = test::imuAnchorRange(robust->state(), 106, z(*robust));
  const double S = innovationVariance(*robust, lin), e = std::abs(lin.residual(0)) / std::sqrt(S);
  const double prior_ratio = (S - lin.R(0, 0)) / lin.R(0, 0);
  if (beyond_k)
    ASSERT_TRUE(e > 2.0 && prior_ratio > 1.0) << "e " << e << ", H P Hᵀ / R " << prior_ratio;
  else
    ASSERT_TRUE(e < 2.0 && prior_ratio < 1.0) << "e " << e << ", H P Hᵀ / R " << prior_ratio;
  const Linearization lin_plain = lin;
  lin.huber_k = 2.0;
  lin.huber_max_prior_ratio = 1.0;
  ASSERT_TRUE(robust->update(lin, 0.0).accepted && plain->update(lin_plain, 0.0).accepted);
  EXPECT_EQ(test::relativeDifference(*robust, *plain), 0.0);
  EXPECT_EQ(crossDifference(*robust, *plain), 0.0);
}

TEST(HuberUpdate, IsThePlainUpdateWithinKAboveThePriorRatioOrWhenGated) {
  for (const std::string name : {"centralized", "dp", "dah"}) {
    SCOPED_TRACE(name);
    // Within k: the range agrees to 1.5 σ.
    expectThePlainUpdate(name, 0.05, [](const FusionStrategy& f) {
      const Linearization lin = test::imuAnchorRange(f.state(), 106, 0.0);
      return -lin.residual(0) + 1.5 * std::sqrt(innovationVariance(f, lin));
    }, false);
    // The state's share of S above the bound (σ_p 0.3 m: H P Hᵀ / R about 3).
    expectThePlainUpdate(name, 0.3, [](const FusionStrategy&) { return 4.0; }, true);
    // Gated on the stated NIS (about 66), not on the weighted one (NIS·k/e, about 16): a gate of
    // 20 between them rejects the range and changes nothing.
    auto robust = makeStrategy(name, 0.05);
    auto before = robust->clone();
    Linearization lin = test::imuAnchorRange(robust->state(), 106, 4.0);
    const double S = innovationVariance(*robust, lin), nis = lin.residual(0) * lin.residual(0) / S;
    ASSERT_GT(nis, 20.0);
    ASSERT_LT(nis * 2.0 / std::sqrt(nis), 20.0);
    lin.huber_k = 2.0;
    const UpdateResult r = robust->update(lin, 20.0);
    EXPECT_FALSE(r.accepted);
    EXPECT_NEAR(r.nis, nis, 1e-9);
    EXPECT_EQ(test::relativeDifference(*robust, *before), 0.0);
    EXPECT_EQ(crossDifference(*robust, *before), 0.0);
  }
}

// Correlated errors (Linearization::step_noise_factor f): the step is the plain update's with R·f,
// the NIS and the gate are those of the stated R, in every strategy; combined with the Huber weight
// the step covariance is (H P Hᵀ + f R)·(√NIS / k).
TEST(StepNoiseFactor, TheStepWeighsRTimesTheFactorTheGateAndTheNisJudgeR) {
  for (const std::string name : {"centralized", "dp", "dah"}) {
    SCOPED_TRACE(name);
    auto weighted = makeStrategy(name, 0.05);
    auto plain = weighted->clone();
    Linearization lin = test::imuAnchorRange(weighted->state(), 106, 3.7);
    const double S = innovationVariance(*weighted, lin), r = lin.residual(0);
    lin.step_noise_factor = 2.5;
    Linearization lin_eff = test::imuAnchorRange(plain->state(), 106, 3.7);
    lin_eff.R(0, 0) *= 2.5;
    const UpdateResult rw = expectThePlainUpdateWithREff(*weighted, lin, *plain, lin_eff);
    EXPECT_NEAR(rw.nis, r * r / S, 1e-12) << "the NIS of the stated R";

    // Gated on the stated R: a gate between the NIS of R and that of R·f rejects the range.
    auto gated = makeStrategy(name, 0.05);
    auto before = gated->clone();
    Linearization far = test::imuAnchorRange(gated->state(), 106, 4.0);
    const double S_far = innovationVariance(*gated, far), nis = far.residual(0) * far.residual(0) / S_far;
    const double nis_inflated = far.residual(0) * far.residual(0) / (S_far + 1.5 * far.R(0, 0));
    const double gate = 0.5 * (nis + nis_inflated);
    ASSERT_LT(nis_inflated, gate);
    far.step_noise_factor = 2.5;
    const UpdateResult rg = gated->update(far, gate);
    EXPECT_FALSE(rg.accepted);
    EXPECT_NEAR(rg.nis, nis, 1e-9);
    EXPECT_EQ(test::relativeDifference(*gated, *before), 0.0);

    // With a Huber weight on top: R_eff = f R + (H P Hᵀ + f R)(e/k − 1), e on the stated S.
    auto both = makeStrategy(name, 0.05);
    auto ref = both->clone();
    Linearization l2 = test::imuAnchorRange(both->state(), 106, 4.0);
    const double S2 = innovationVariance(*both, l2), e = std::abs(l2.residual(0)) / std::sqrt(S2);
    ASSERT_GT(e, 2.0);
    l2.step_noise_factor = 2.5;
    l2.huber_k = 2.0;
    l2.huber_max_prior_ratio = 1.0;
    Linearization l2_eff = test::imuAnchorRange(ref->state(), 106, 4.0);
    const double R = l2_eff.R(0, 0);
    l2_eff.R(0, 0) = 2.5 * R + (S2 + 1.5 * R) * (e / 2.0 - 1.0);
    expectThePlainUpdateWithREff(*both, l2, *ref, l2_eff);
  }
}
