#include <gtest/gtest.h>

#include <cmath>

#include "eval/trajectory_metrics.h"

using namespace meshnav;
using namespace meshnav::eval;

namespace {

Eigen::Quaterniond expSO3(const Eigen::Vector3d& v) {
  const double a = v.norm();
  if (a < 1e-15) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(a, v / a));
}

/// Ground truth: straight line along x at 1 m/s, yawing at 0.1 rad/s, sampled at 10 Hz for 10 s.
std::vector<PoseSample> groundTruth() {
  std::vector<PoseSample> gt;
  for (int k = 0; k <= 100; ++k) {
    const double t = 0.1 * k;
    gt.push_back({Timestamp::fromSec(t), Eigen::Vector3d(t, 0.0, 2.0),
                  Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * t, Eigen::Vector3d::UnitZ()))});
  }
  return gt;
}

PoseEstimate truthAsEstimate(double t) {
  PoseEstimate e;
  e.t = Timestamp::fromSec(t);
  e.p_IinG = Eigen::Vector3d(t, 0.0, 2.0);
  e.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * t, Eigen::Vector3d::UnitZ()));
  e.cov_p_m2 = Eigen::Matrix3d::Identity() * 0.01;
  e.cov_theta_rad2 = Eigen::Matrix3d::Identity() * 1e-4;
  return e;
}

}  // namespace

TEST(PoseError, LogSO3RoundTrip) {
  const Eigen::Vector3d v(0.3, -0.2, 1.1);
  EXPECT_TRUE(logSO3(expSO3(v)).isApprox(v, 1e-12));
  EXPECT_TRUE(logSO3(Eigen::Quaterniond::Identity()).isZero());
  // q and −q are the same rotation.
  Eigen::Quaterniond q = expSO3(v);
  q.coeffs() *= -1.0;
  EXPECT_TRUE(logSO3(q).isApprox(v, 1e-12));
}

TEST(PoseError, SignConventionsMatchTheFilterErrorState) {
  const PoseSample truth{Timestamp::fromSec(1.0), Eigen::Vector3d(1, 2, 3),
                         Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 1, 0).normalized()))};
  const Eigen::Vector3d dtheta(0.02, -0.01, 0.05);
  PoseEstimate est;
  est.t = truth.t;
  est.p_IinG = truth.p_IinG - Eigen::Vector3d(0.1, 0.0, -0.2);
  // R_true = R̂ · Exp(δθ)  ⇔  R̂ = R_true · Exp(−δθ)
  est.q_ItoG = truth.q_ItoG * expSO3(-dtheta);
  const PoseError e = computePoseError(est, truth);
  EXPECT_TRUE(e.p_err_m.isApprox(Eigen::Vector3d(0.1, 0.0, -0.2), 1e-12));
  EXPECT_TRUE(e.theta_err_rad.isApprox(dtheta, 1e-9));
  EXPECT_NEAR(e.orientationErrorDeg(), dtheta.norm() * 180.0 / M_PI, 1e-9);
  // No covariance → no NEES.
  EXPECT_FALSE(e.nees_p.has_value());
  EXPECT_FALSE(e.nees_theta.has_value());
}

TEST(TrajectoryMetrics, ConstantOffsetGivesEqualRmseAndArmse) {
  const auto gt = groundTruth();
  std::vector<PoseEstimate> est;
  for (int k = 0; k < 50; ++k) {
    auto e = truthAsEstimate(0.05 + 0.2 * k);  // between GT samples: interpolation needed
    e.p_IinG -= Eigen::Vector3d(0.3, 0.4, 0.0);  // error truth − estimate = (0.3, 0.4, 0), norm 0.5
    est.push_back(e);
  }
  Diagnostics diag;
  EvalOptions opt;
  const auto errors = associate(est, gt, {}, opt, diag);
  ASSERT_EQ(errors.size(), est.size());
  const auto m = computeTrajectoryMetrics(errors, opt);
  EXPECT_EQ(m.position.n, 50);
  EXPECT_NEAR(m.position.rmse, 0.5, 1e-9);
  EXPECT_NEAR(m.position.armse, 0.5, 1e-9);
  EXPECT_NEAR(m.position.max, 0.5, 1e-9);
  EXPECT_NEAR(m.position.rmse_axes.x(), 0.3, 1e-9);
  EXPECT_NEAR(m.position.rmse_axes.y(), 0.4, 1e-9);
  EXPECT_NEAR(m.position.rmse_axes.z(), 0.0, 1e-9);
  EXPECT_NEAR(m.orientation.rmse, 0.0, 1e-6);  // slerped truth matches exactly
  // NEES with P = 0.01 I: 0.25 / 0.01 = 25.
  EXPECT_NEAR(m.position.anees, 25.0, 1e-6);
  EXPECT_FALSE(m.position.anees_bounds.contains(m.position.anees));
}

TEST(TrajectoryMetrics, RmseAndArmseDifferForVaryingErrors) {
  const auto gt = groundTruth();
  std::vector<PoseEstimate> est;
  for (int k = 0; k < 10; ++k) {
    auto e = truthAsEstimate(0.5 * k);
    e.p_IinG.z() -= (k % 2 == 0) ? 1.0 : 3.0;  // norms 1 and 3 alternately
    est.push_back(e);
  }
  Diagnostics diag;
  const auto m = computeTrajectoryMetrics(associate(est, gt, {}, {}, diag), {});
  EXPECT_NEAR(m.position.rmse, std::sqrt(5.0), 1e-9);  // √((1 + 9) / 2)
  EXPECT_NEAR(m.position.armse, 2.0, 1e-9);            // (1 + 3) / 2
  EXPECT_NEAR(m.position.max, 3.0, 1e-9);
}

TEST(TrajectoryMetrics, KnownRotationErrorInDegrees) {
  const auto gt = groundTruth();
  const Eigen::Vector3d dtheta = Eigen::Vector3d(1.0, 2.0, 2.0).normalized() * (10.0 * M_PI / 180.0);
  std::vector<PoseEstimate> est;
  for (int k = 0; k < 20; ++k) {
    auto e = truthAsEstimate(0.3 + 0.4 * k);
    e.q_ItoG = e.q_ItoG * expSO3(-dtheta);
    est.push_back(e);
  }
  Diagnostics diag;
  const auto errors = associate(est, gt, {}, {}, diag);
  for (const auto& e : errors) EXPECT_TRUE(e.theta_err_rad.isApprox(dtheta, 1e-9));
  const auto m = computeTrajectoryMetrics(errors, {});
  EXPECT_NEAR(m.orientation.rmse, 10.0, 1e-7);
  EXPECT_NEAR(m.orientation.armse, 10.0, 1e-7);
  EXPECT_NEAR(m.position.rmse, 0.0, 1e-9);
}

TEST(TrajectoryMetrics, CovarianceScaledErrorsGiveNeesExactlyThree) {
  // Error e = (a, b, c) with covariance diag(a², b², c²): each axis contributes 1 → NEES 3.
  // A rotated full covariance R diag(a², b², c²) Rᵀ with error R (a, b, c) gives the same.
  const auto gt = groundTruth();
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  std::vector<PoseEstimate> est;
  for (int k = 0; k < 30; ++k) {
    auto e = truthAsEstimate(0.25 + 0.3 * k);
    const Eigen::Vector3d sig(0.1 + 0.01 * k, 0.2, 0.05 + 0.002 * k);
    const Eigen::Vector3d err_p = R * sig;
    e.p_IinG -= err_p;
    e.cov_p_m2 = R * sig.cwiseAbs2().asDiagonal() * R.transpose();
    const Eigen::Vector3d sig_th = sig * 0.1;
    e.q_ItoG = e.q_ItoG * expSO3(-sig_th);
    e.cov_theta_rad2 = sig_th.cwiseAbs2().asDiagonal();
    est.push_back(e);
  }
  Diagnostics diag;
  const auto errors = associate(est, gt, {}, {}, diag);
  for (const auto& e : errors) {
    ASSERT_TRUE(e.nees_p && e.nees_theta);
    EXPECT_NEAR(*e.nees_p, 3.0, 1e-9);
    EXPECT_NEAR(*e.nees_theta, 3.0, 1e-6);
  }
  const auto m = computeTrajectoryMetrics(errors, {});
  EXPECT_EQ(m.position.n_nees, 30);
  EXPECT_NEAR(m.position.anees, 3.0, 1e-9);
  EXPECT_NEAR(m.orientation.anees, 3.0, 1e-6);
  EXPECT_TRUE(m.position.anees_bounds.contains(3.0));
  EXPECT_NEAR(m.position.frac_nees_in_single_bounds, 1.0, 1e-12);
}

TEST(TrajectoryMetrics, SingularCovarianceIsExcludedFromNeesOnly) {
  const auto gt = groundTruth();
  std::vector<PoseEstimate> est = {truthAsEstimate(1.0), truthAsEstimate(2.0)};
  est[1].cov_p_m2.setZero();
  est[0].p_IinG.x() -= 0.1;  // NEES 1
  Diagnostics diag;
  const auto m = computeTrajectoryMetrics(associate(est, gt, {}, {}, diag), {});
  EXPECT_EQ(m.position.n, 2);
  EXPECT_EQ(m.position.n_nees, 1);
  EXPECT_NEAR(m.position.anees, 1.0, 1e-9);
}

TEST(Association, InterpolatesGroundTruthAndSkipsOutsideIt) {
  std::vector<PoseSample> gt = {
      {Timestamp::fromSec(0.0), Eigen::Vector3d(0, 0, 0), Eigen::Quaterniond::Identity()},
      {Timestamp::fromSec(1.0), Eigen::Vector3d(1, 2, 0), Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()))},
      {Timestamp::fromSec(5.0), Eigen::Vector3d(1, 2, 0), Eigen::Quaterniond::Identity()}};  // gap 1–5 s
  PoseEstimate mid;
  mid.t = Timestamp::fromSec(0.25);
  mid.p_IinG = Eigen::Vector3d(0.25, 0.5, 0.0);
  mid.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()));
  PoseEstimate before = mid, in_gap = mid, after = mid;
  before.t = Timestamp::fromSec(-0.5);
  in_gap.t = Timestamp::fromSec(3.0);
  after.t = Timestamp::fromSec(6.0);
  Diagnostics diag;
  EvalOptions opt;
  opt.max_gt_gap_s = 2.0;  // the 1 s spacing is interpolated, the 4 s gap is not
  const auto errors = associate({before, mid, in_gap, after}, gt, {}, opt, diag);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].t, mid.t);
  EXPECT_LT(errors[0].p_err_m.norm(), 1e-12);
  EXPECT_LT(errors[0].theta_err_rad.norm(), 1e-12);
  EXPECT_EQ(diag.get("eval:outside_ground_truth"), 3);
}

TEST(Selection, SkipFirstSecondsAndOnlyFlying) {
  const auto gt = groundTruth();
  std::vector<PoseEstimate> est;
  for (int k = 0; k <= 9; ++k) {
    auto e = truthAsEstimate(1.0 + k);  // t = 1..10 s
    e.p_IinG.x() -= (k < 3) ? 10.0 : 0.1;  // large errors in the first 3 samples
    est.push_back(e);
  }
  const std::vector<FlightStateSample> flight = {{Timestamp::fromSec(0.0), true},
                                                 {Timestamp::fromSec(2.5), false},
                                                 {Timestamp::fromSec(8.5), true}};
  Diagnostics diag;
  EvalOptions all;
  auto errors = associate(est, gt, flight, all, diag);
  ASSERT_EQ(errors.size(), 10u);
  EXPECT_FALSE(errors[0].flying);  // t = 1 landed
  EXPECT_TRUE(errors[2].flying);   // t = 3
  EXPECT_FALSE(errors[8].flying);  // t = 9 landed again

  EvalOptions skip;
  skip.skip_first_s = 3.0;  // t − 1 s ≥ 3 s → t ≥ 4 s: 7 samples, all with 0.1 m error
  auto m = computeTrajectoryMetrics(errors, skip);
  EXPECT_EQ(m.n_selected, 7);
  EXPECT_NEAR(m.position.rmse, 0.1, 1e-9);
  EXPECT_NEAR(m.t_first_s, 4.0, 1e-9);

  EvalOptions flying;
  flying.only_flying = true;  // t = 3..8 s → 6 samples, first with 10 m error
  m = computeTrajectoryMetrics(errors, flying);
  EXPECT_EQ(m.n_selected, 6);
  EXPECT_NEAR(m.position.max, 10.0, 1e-9);
}

TEST(TrajectoryMetrics, EmptyInputGivesNaNNotACrash) {
  const auto m = computeTrajectoryMetrics({}, {});
  EXPECT_EQ(m.n_selected, 0);
  EXPECT_TRUE(std::isnan(m.position.rmse));
  EXPECT_TRUE(std::isnan(m.position.anees));
}
