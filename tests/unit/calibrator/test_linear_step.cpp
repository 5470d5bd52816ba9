// The linear (optimal double) step: unbiased on average over many noisy seeds, pair selection.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "calibrator/calibration_problem.h"
#include "calibrator/optimal_double_solver.h"
#include "calibrator/synthetic_scene.h"

using namespace meshnav::calib;

namespace {

struct MonteCarlo {
  Eigen::Vector3d mean_err = Eigen::Vector3d::Zero();
  Eigen::Vector3d std_err = Eigen::Vector3d::Zero();  ///< standard error of the mean
  double mean_gamma_err = 0.0;                        ///< tag 100
  double se_gamma = 0.0;
};

MonteCarlo run(bool bias_correction, int n_seeds, double sigma) {
  std::vector<Eigen::Vector3d> errs;
  std::vector<double> gerr;
  CalibratorOptions o;
  o.linear_bias_correction = bias_correction;
  const OptimalDoubleSolver solver(o);
  for (int s = 1; s <= n_seeds; ++s) {
    SyntheticSceneConfig cfg;
    cfg.sigma_d_m = sigma;
    cfg.n_ranges = 400;
    cfg.seed = static_cast<uint64_t>(1000 + s);
    const auto sc = makeSyntheticScene(cfg);
    const CalibrationProblem pb(106, sc.observations, {}, o);
    const auto sol = solver.solve(pb);
    EXPECT_TRUE(sol.ok) << sol.reason;
    errs.push_back(sol.params.p_AinG - sc.p_AinG);
    gerr.push_back(sol.params.gamma_m[0] - sc.gamma_m.at(100));
  }
  MonteCarlo mc;
  for (const auto& e : errs) mc.mean_err += e;
  mc.mean_err /= n_seeds;
  for (const auto& e : errs) mc.std_err += (e - mc.mean_err).cwiseAbs2();
  mc.std_err = (mc.std_err / (n_seeds - 1)).cwiseSqrt() / std::sqrt(n_seeds);
  for (double g : gerr) mc.mean_gamma_err += g / n_seeds;
  double v = 0;
  for (double g : gerr) v += std::pow(g - mc.mean_gamma_err, 2);
  mc.se_gamma = std::sqrt(v / (n_seeds - 1)) / std::sqrt(n_seeds);
  return mc;
}

}  // namespace

TEST(LinearStep, UnbiasedOverManyNoisySeeds) {
  const int n = 400;
  const double sigma = 0.2;
  const MonteCarlo naive = run(false, n, sigma);
  const MonteCarlo corrected = run(true, n, sigma);
  std::printf("naive (z1-z2 regressor):      mean error [%+.4f %+.4f %+.4f] m (SE %.4f %.4f %.4f), gamma %+.4f (SE %.4f)\n",
              naive.mean_err.x(), naive.mean_err.y(), naive.mean_err.z(), naive.std_err.x(), naive.std_err.y(),
              naive.std_err.z(), naive.mean_gamma_err, naive.se_gamma);
  std::printf("predicted-distance regressor: mean error [%+.4f %+.4f %+.4f] m (SE %.4f %.4f %.4f), gamma %+.4f (SE %.4f)\n",
              corrected.mean_err.x(), corrected.mean_err.y(), corrected.mean_err.z(), corrected.std_err.x(),
              corrected.std_err.y(), corrected.std_err.z(), corrected.mean_gamma_err, corrected.se_gamma);
  // Unbiased: every component of the mean error within 4 standard errors of zero.
  for (int k = 0; k < 3; ++k) EXPECT_LT(std::abs(corrected.mean_err(k)), 4.0 * corrected.std_err(k) + 1e-4) << "axis " << k;
  EXPECT_LT(std::abs(corrected.mean_gamma_err), 4.0 * corrected.se_gamma + 1e-4);
  // The paper's regressor z1 − z2 is measurably biased (errors in variables) on γ.
  EXPECT_GT(std::abs(naive.mean_gamma_err), 4.0 * naive.se_gamma);
}

TEST(LinearStep, PairsAreDisjointAndFarApart) {
  SyntheticSceneConfig cfg;
  const auto sc = makeSyntheticScene(cfg);
  const CalibratorOptions o;
  const CalibrationProblem pb(106, sc.observations, {}, o);
  const auto& slot = pb.slots()[0];
  ASSERT_TRUE(slot.moving);
  std::vector<double> rho, var;
  for (int i : slot.obs) {
    rho.push_back(pb.observations()[static_cast<size_t>(i)].z_m);
    var.push_back(1.0);
  }
  const auto pairs = OptimalDoubleSolver::selectPairs(pb, slot.obs, rho, var);
  ASSERT_GE(pairs.size(), slot.obs.size() / 2 - 2);
  std::set<int> used;
  double mean_sep = 0, mean_adjacent = 0;
  for (auto [i, j] : pairs) {
    EXPECT_TRUE(used.insert(i).second);
    EXPECT_TRUE(used.insert(j).second);
    mean_sep += (pb.observations()[static_cast<size_t>(i)].p_RinG - pb.observations()[static_cast<size_t>(j)].p_RinG).norm();
  }
  mean_sep /= static_cast<double>(pairs.size());
  for (size_t k = 0; k + 1 < slot.obs.size(); ++k)
    mean_adjacent += (pb.observations()[static_cast<size_t>(slot.obs[k])].p_RinG -
                      pb.observations()[static_cast<size_t>(slot.obs[k + 1])].p_RinG).norm();
  mean_adjacent /= static_cast<double>(slot.obs.size() - 1);
  EXPECT_GT(mean_sep, 5.0 * mean_adjacent);
}

TEST(LinearStep, StationaryReferencesGetTheirBiasFromTheMeanResidual) {
  SyntheticSceneConfig cfg;
  cfg.sigma_d_m = 0.0;
  cfg.model_sigma_d_m = 0.1;
  const auto sc = makeSyntheticScene(cfg);
  const CalibratorOptions o;
  const CalibrationProblem pb(106, sc.observations, {}, o);
  const auto sol = OptimalDoubleSolver(o).solve(pb);
  ASSERT_TRUE(sol.ok);
  for (size_t k = 0; k < pb.slots().size(); ++k) {
    EXPECT_EQ(pb.slots()[k].moving, pb.slots()[k].id == 100 || pb.slots()[k].id == 105);
    EXPECT_NEAR(sol.params.gamma_m[k], sc.gamma_m.at(pb.slots()[k].id), 1e-8);
  }
}

TEST(LinearStep, RefusesWithoutMovingReference) {
  SyntheticSceneConfig cfg;
  cfg.path = SyntheticPath::Hover;
  const auto sc = makeSyntheticScene(cfg);
  const CalibratorOptions o;
  const CalibrationProblem pb(106, sc.observations, {}, o);
  const auto sol = OptimalDoubleSolver(o).solve(pb);
  EXPECT_FALSE(sol.ok);
  EXPECT_NE(sol.reason.find("moving"), std::string::npos);
}
