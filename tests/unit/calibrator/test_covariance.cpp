// Covariance of the initial belief: NEES consistency over many seeds, and the Cramér–Rao bound.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>

#include "calibrator/anchor_calibrator.h"
#include "calibrator/calibration_problem.h"
#include "calibrator/range_model.h"
#include "calibrator/synthetic_scene.h"

using namespace meshnav::calib;

namespace {

constexpr double kChi2_3_997 = 13.93;  // 99.7 % quantile of χ²(3)

struct Stats {
  double pass_rate = 0, mean_nees = 0, rmse = 0, mean_crb = 0;
};

Stats monteCarlo(SyntheticSceneConfig cfg, const CalibratorOptions& o, int n) {
  Stats st;
  int pass = 0;
  for (int s = 1; s <= n; ++s) {
    cfg.seed = static_cast<uint64_t>(500 + s);
    const auto sc = makeSyntheticScene(cfg);
    const auto r = AnchorCalibrator(o).calibrate(106, sc.observations);
    EXPECT_TRUE(r.ok()) << r.reason;
    if (!r.ok()) continue;
    const Eigen::Vector3d e = r.p_AinG - sc.p_AinG;
    const double nees = e.dot(r.cov_p_m2.ldlt().solve(e));
    pass += nees <= kChi2_3_997 ? 1 : 0;
    st.mean_nees += nees / n;
    st.rmse += e.squaredNorm() / n;
    const CalibrationProblem pb(106, sc.observations, {}, o);
    AnchorParams truth = pb.priorParams(sc.p_AinG);
    for (size_t k = 0; k < pb.slots().size(); ++k) {
      truth.gamma_m[k] = sc.gamma_m.at(pb.slots()[k].id);
      truth.beta[k] = sc.beta.at(pb.slots()[k].id);
    }
    st.mean_crb += crbPositionRmse(pb, truth) / n;
  }
  st.pass_rate = static_cast<double>(pass) / n;
  st.rmse = std::sqrt(st.rmse);
  return st;
}

void print(const char* name, const Stats& s) {
  std::printf("%-40s NEES pass %.3f  mean NEES %.2f  RMSE %.4f m  CRB %.4f m\n", name, s.pass_rate, s.mean_nees, s.rmse,
              s.mean_crb);
}

}  // namespace

TEST(Covariance, ConsistentWithNoiseOnly) {
  SyntheticSceneConfig cfg;
  const Stats s = monteCarlo(cfg, CalibratorOptions{}, 150);
  print("sigma_d 0.1", s);
  EXPECT_GE(s.pass_rate, 0.95);
  EXPECT_LT(s.mean_nees, 4.5);
  // Efficient: the RMS error is close to the Cramér–Rao bound of the same data.
  EXPECT_LT(s.rmse, 1.5 * s.mean_crb);
  EXPECT_GT(s.rmse, 0.6 * s.mean_crb);
}

TEST(Covariance, ConsistentWithReferenceNoiseOutliersAndUnderstatedSigma) {
  SyntheticSceneConfig cfg;
  cfg.sigma_d_m = 0.15;
  cfg.model_sigma_d_m = 0.1;  // the calibrator is told 0.1: residual scaling must cover it
  cfg.sigma_ref_m = 0.05;     // tag positions from an estimator
  cfg.outlier_fraction = 0.1;
  cfg.beta_sigma = 0.005;
  for (bool ransac : {true, false}) {
    CalibratorOptions o;
    o.ransac = ransac;
    const Stats s = monteCarlo(cfg, o, 120);
    print(ransac ? "noisy refs + outliers, RANSAC" : "noisy refs + outliers, no RANSAC", s);
    EXPECT_GE(s.pass_rate, 0.95);
  }
}

TEST(Covariance, CramerRaoBoundShrinksWithMoreData) {
  SyntheticSceneConfig cfg;
  const CalibratorOptions o;
  double prev = 1e9;
  for (int n : {200, 700, 2800}) {
    cfg.n_ranges = n;
    const auto sc = makeSyntheticScene(cfg);
    const CalibrationProblem pb(106, sc.observations, {}, o);
    const double crb = crbPositionRmse(pb, pb.priorParams(sc.p_AinG));
    EXPECT_TRUE(std::isfinite(crb));
    EXPECT_LT(crb, prev);
    prev = crb;
  }
}

TEST(Covariance, StationaryReferencesAloneGivePositionOnlyThroughTheGammaPrior) {
  // Information of a known anchor on p vanishes when its γ is free without prior.
  SyntheticSceneConfig cfg;
  cfg.path = SyntheticPath::Hover;
  const auto sc = makeSyntheticScene(cfg);
  std::vector<CalibObservation> anchors_only;
  for (const auto& ob : sc.observations)
    if (ob.ref_id > 100 && ob.ref_id != 105) anchors_only.push_back(ob);
  CalibratorOptions o;
  o.gamma_prior_sigma_m = 0.0;
  const CalibrationProblem pb(106, anchors_only, {}, o);
  const Eigen::MatrixXd H = informationMatrix(pb, pb.priorParams(sc.p_AinG), {}, true);
  Eigen::MatrixXd marg = H.topLeftCorner(3, 3) -
                         H.topRightCorner(3, H.cols() - 3) * H.bottomRightCorner(H.rows() - 3, H.cols() - 3).inverse() *
                             H.bottomLeftCorner(H.rows() - 3, 3);
  EXPECT_LT(marg.norm(), 1e-6 * H.topLeftCorner(3, 3).norm());
  o.gamma_prior_sigma_m = 0.25;
  const CalibrationProblem pb2(106, anchors_only, {}, o);
  const Eigen::MatrixXd H2 = informationMatrix(pb2, pb2.priorParams(sc.p_AinG), {}, true);
  marg = H2.topLeftCorner(3, 3) - H2.topRightCorner(3, H2.cols() - 3) *
                                      H2.bottomRightCorner(H2.rows() - 3, H2.cols() - 3).inverse() *
                                      H2.bottomLeftCorner(H2.rows() - 3, 3);
  EXPECT_GT(marg.norm(), 1.0);  // ≈ Σ u uᵀ/0.25² over the four anchors
}
