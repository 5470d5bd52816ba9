// Noise-free ranges: the calibration recovers the anchor position and every pair bias exactly.
#include <gtest/gtest.h>

#include "calibrator/anchor_calibrator.h"
#include "calibrator/calibration_problem.h"
#include "calibrator/optimal_double_solver.h"
#include "calibrator/synthetic_scene.h"

using namespace meshnav::calib;

namespace {

SyntheticScene noiseFreeScene(uint64_t seed, double beta_sigma) {
  SyntheticSceneConfig cfg;
  cfg.sigma_d_m = 0.0;
  cfg.model_sigma_d_m = 0.1;  // the calibrator still assumes noise
  cfg.beta_sigma = beta_sigma;
  cfg.seed = seed;
  return makeSyntheticScene(cfg);
}

CalibratorOptions noPriors() {
  CalibratorOptions o;
  o.gamma_prior_sigma_m = 0.0;  // a prior would (correctly) pull the MAP estimate off the truth
  o.beta_prior_sigma = 0.0;
  return o;
}

void expectExact(const CalibrationResult& r, const SyntheticScene& sc) {
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_LT((r.p_AinG - sc.p_AinG).norm(), 1e-6);
  ASSERT_EQ(r.references.size(), 6u);
  for (const auto& ref : r.references) {
    EXPECT_NEAR(ref.gamma_m, sc.gamma_m.at(ref.ref_id), 1e-6) << "reference " << ref.ref_id;
    EXPECT_NEAR(ref.beta, sc.beta.at(ref.ref_id), 1e-6) << "reference " << ref.ref_id;
  }
  EXPECT_EQ(r.n_outliers, 0);
}

}  // namespace

TEST(NoiseFree, LinearStepIsExactWithUnitBeta) {
  const auto sc = noiseFreeScene(3, 0.0);
  const CalibratorOptions o = noPriors();
  const CalibrationProblem pb(106, sc.observations, {}, o);
  for (bool corr : {false, true}) {
    CalibratorOptions oc = o;
    oc.linear_bias_correction = corr;
    const LinearSolution s = OptimalDoubleSolver(oc).solve(pb);
    ASSERT_TRUE(s.ok) << s.reason;
    EXPECT_LT((s.params.p_AinG - sc.p_AinG).norm(), 1e-8);
    for (size_t k = 0; k < pb.slots().size(); ++k)
      EXPECT_NEAR(s.params.gamma_m[k], sc.gamma_m.at(pb.slots()[k].id), 1e-8);
  }
}

TEST(NoiseFree, RefinementRecoversPositionAndBiases) {
  for (uint64_t seed : {1, 2, 3}) {
    const auto sc = noiseFreeScene(seed, 0.01);  // tag pairs with β ≠ 1
    expectExact(AnchorCalibrator(noPriors()).calibrate(106, sc.observations), sc);
  }
}

TEST(NoiseFree, WithoutRansacAndWithoutRobustLoss) {
  const auto sc = noiseFreeScene(4, 0.01);
  CalibratorOptions o = noPriors();
  o.ransac = false;
  o.robust_loss = RobustLoss::None;
  expectExact(AnchorCalibrator(o).calibrate(106, sc.observations), sc);
}

TEST(NoiseFree, OtherAnchorsOfTheHall) {
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(-2.021, 1.814, 1.732), Eigen::Vector3d(0.433, 4.105, 0.925),
                                  Eigen::Vector3d(2.59, -0.2, 0.33)}) {
    SyntheticSceneConfig cfg;
    cfg.sigma_d_m = 0.0;
    cfg.model_sigma_d_m = 0.1;
    cfg.p_AinG = p;
    const auto sc = makeSyntheticScene(cfg);
    expectExact(AnchorCalibrator(noPriors()).calibrate(107, sc.observations), sc);
  }
}
