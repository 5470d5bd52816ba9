// RANSAC: removes injected outliers, is reproducible for a fixed seed.
#include <gtest/gtest.h>

#include "calibrator/anchor_calibrator.h"
#include "calibrator/calibration_problem.h"
#include "calibrator/ransac_solver.h"
#include "calibrator/synthetic_scene.h"

using namespace meshnav::calib;

namespace {
SyntheticScene outlierScene(uint64_t seed, double fraction) {
  SyntheticSceneConfig cfg;
  cfg.sigma_d_m = 0.1;
  cfg.outlier_fraction = fraction;
  cfg.seed = seed;
  return makeSyntheticScene(cfg);
}
}  // namespace

TEST(Ransac, RejectsInjectedOutliers) {
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    const auto sc = outlierScene(seed, 0.15);
    const CalibratorOptions o;  // RANSAC on
    const auto r = AnchorCalibrator(o).calibrate(106, sc.observations);
    ASSERT_TRUE(r.ok()) << r.reason;
    int caught = 0, injected = 0, good_rejected = 0, good = 0;
    for (size_t i = 0; i < sc.observations.size(); ++i) {
      const auto& o = sc.observations[i];
      const double true_err = o.z_m - sc.beta.at(o.ref_id) * (sc.p_AinG - o.p_RinG).norm() - sc.gamma_m.at(o.ref_id);
      if (sc.is_outlier[i] && true_err > 0.4) {  // 4σ: unmistakable (a 0.5 m excess plus −0.2 m noise is not)
        ++injected;
        caught += r.inliers[i] ? 0 : 1;
      } else if (!sc.is_outlier[i]) {
        ++good;
        good_rejected += r.inliers[i] ? 0 : 1;
      }
    }
    // Every unmistakable outlier must go; few good ranges may.
    EXPECT_EQ(caught, injected) << "seed " << seed;
    EXPECT_GT(injected, 50);
    EXPECT_LT(good_rejected, good / 50) << "seed " << seed;
    EXPECT_LT((r.p_AinG - sc.p_AinG).norm(), 0.1) << "seed " << seed;
  }
}

TEST(Ransac, HypothesisSupportFindsTheInliers) {
  const auto sc = outlierScene(11, 0.3);  // heavy contamination, still found
  const CalibratorOptions o;
  const CalibrationProblem pb(106, sc.observations, {}, o);
  const auto rr = RansacSolver(o).run(pb, 42);
  ASSERT_TRUE(rr.ok) << rr.reason;
  EXPECT_GE(rr.iterations, o.ransac_min_iterations);
  EXPECT_LT((rr.solution.params.p_AinG - sc.p_AinG).norm(), 0.3);
  int inl = 0;
  for (size_t i = 0; i < pb.observations().size(); ++i) inl += rr.inliers[i] ? 1 : 0;
  EXPECT_EQ(inl, rr.n_inliers);
  EXPECT_GT(rr.n_inliers, static_cast<int>(0.6 * pb.observations().size()));
}

TEST(Ransac, ReproducibleForAFixedSeed) {
  const auto sc = outlierScene(3, 0.15);
  CalibratorOptions o;
  o.ransac_seed = 1234;
  const auto a = AnchorCalibrator(o).calibrate(106, sc.observations);
  const auto b = AnchorCalibrator(o).calibrate(106, sc.observations);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a.p_AinG, b.p_AinG);  // bitwise
  EXPECT_EQ(a.cov_p_m2, b.cov_p_m2);
  EXPECT_EQ(a.inliers, b.inliers);
  EXPECT_EQ(a.ransac_iterations, b.ransac_iterations);

  const CalibrationProblem pb(106, sc.observations, {}, o);
  const auto r1 = RansacSolver(o).run(pb, 7);
  const auto r2 = RansacSolver(o).run(pb, 7);
  EXPECT_EQ(r1.inliers, r2.inliers);
  EXPECT_EQ(r1.solution.params.p_AinG, r2.solution.params.p_AinG);
}

TEST(Ransac, AdaptiveIterationCountFollowsInlierRatio) {
  const CalibratorOptions o;
  const auto clean = outlierScene(5, 0.0);
  const auto dirty = outlierScene(5, 0.3);
  const CalibrationProblem pc(106, clean.observations, {}, o), pd(106, dirty.observations, {}, o);
  const auto rc = RansacSolver(o).run(pc, 1);
  const auto rd = RansacSolver(o).run(pd, 1);
  ASSERT_TRUE(rc.ok && rd.ok);
  EXPECT_LE(rc.iterations, rd.iterations);
  EXPECT_LE(rd.iterations, o.ransac_max_iterations);
}
