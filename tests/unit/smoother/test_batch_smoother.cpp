/// @file test_batch_smoother.cpp
/// @brief The whole-recording smoother on the analytic scenario (estimator/testing): exact answers
/// from noise-free data and a poor start, outliers under the robust loss, a small NLOS excess under
/// the NLOS mixture, an anchor frame with z down, a filter that re-initialized, and the
/// consistency of its covariance on noisy data.

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

#include "estimator/core/estimator_options.h"
#include "estimator/core/so3.h"
#include "estimator/testing/synthetic_scenario.h"
#include "smoother/run_smoother.h"
#include "smoother/testing/perturbed_run.h"

using namespace meshnav;
using namespace meshnav::smoother;
using estimator::so3::expMap;
using estimator::so3::logMap;
namespace syn = meshnav::estimator::synthetic;
using meshnav::smoother::testing::perturbedRun;

namespace {

struct Errors {
  double pos_rms_m = 0.0, ori_rms_deg = 0.0, anees_p = 0.0, anees_theta = 0.0;
};

Errors errorsAgainstTruth(const Dataset& ds, const SmoothedRun& sm) {
  Errors e;
  size_t j = 0;
  int n = 0;
  for (const auto& p : sm.poses) {
    while (j < ds.ground_truth.size() && ds.ground_truth[j].t < p.t) ++j;
    if (j >= ds.ground_truth.size() || ds.ground_truth[j].t != p.t) continue;
    const auto& g = ds.ground_truth[j];
    const Eigen::Vector3d dp = p.p_IinG - g.p_IinG;
    e.pos_rms_m += dp.squaredNorm();
    // Local orientation error δθ = Log(R̂ᵀ R) (R = R̂ Exp(δθ)), the frame of cov_theta_rad2.
    const Eigen::Vector3d dth =
        logMap(Eigen::Matrix3d(p.q_ItoG.toRotationMatrix().transpose() * g.q_ItoG.toRotationMatrix()));
    e.ori_rms_deg += dth.squaredNorm();
    e.anees_p += dp.dot(p.cov_p_m2.inverse() * dp);
    e.anees_theta += dth.dot(p.cov_theta_rad2.inverse() * dth);
    ++n;
  }
  EXPECT_GT(n, 100);
  e.pos_rms_m = std::sqrt(e.pos_rms_m / n);
  e.ori_rms_deg = std::sqrt(e.ori_rms_deg / n) * 180.0 / M_PI;
  e.anees_p /= n;
  e.anees_theta /= n;
  return e;
}

/// Noise-free data: the smoothed trajectory is the true one (to the solver's tolerance).
void expectExact(const Dataset& ds, const SmoothedRun& sm) {
  const Errors e = errorsAgainstTruth(ds, sm);
  EXPECT_LT(e.pos_rms_m, 0.005);
  EXPECT_LT(e.ori_rms_deg, 0.05);
}

syn::SyntheticOptions scenario(bool noise) {
  syn::SyntheticOptions o;
  o.duration_s = 30.0;
  o.pair_rate_hz = 5.0;
  o.anchor_to_anchor = false;
  o.noise = noise;
  o.seed = 3;
  return o;
}

}  // namespace

TEST(BatchSmoother, RecoversTheTrajectoryExactlyFromNoiseFreeDataAndAPoorStart) {
  const Dataset ds = syn::makeSyntheticDataset(scenario(false));
  const FilterRun run = perturbedRun(ds, 0.3, 5.0);
  const SmoothedRun sm = smoothRun(ds, run, RunSmootherOptions{});
  ASSERT_EQ(sm.chunks.size(), 1u);
  EXPECT_TRUE(sm.chunks[0].result.converged) << sm.chunks[0].result.message;
  EXPECT_TRUE(sm.chunks[0].result.covariance_ok);
  EXPECT_EQ(sm.chunks[0].gravity_z_sign, -1.0);
  expectExact(ds, sm);
  EXPECT_EQ(sm.chunks[0].result.n_range_outliers, 0);
}

TEST(BatchSmoother, ChunksGiveTheSameTrajectoryAsOneSolve) {
  const Dataset ds = syn::makeSyntheticDataset(scenario(false));
  // Each chunk after the first starts from the filter's belief there: exact poses (σ 1 cm, 0.5°),
  // so that the chunks' answer is the exact one too.
  const FilterRun run = perturbedRun(ds, 0.0, 0.0);
  RunSmootherOptions o;
  o.chunk_s = 12.0;
  o.overlap_s = 4.0;
  const SmoothedRun sm = smoothRun(ds, run, o);
  EXPECT_GE(sm.chunks.size(), 3u);
  expectExact(ds, sm);
  // On noisy data each chunk starts from a filter-like prior (0.1 m, 2° off, covered by its σ): the
  // chunked answer is about as good as one solve's and as consistent (a prior counted twice or
  // lost would show in its ANEES).
  const Dataset noisy = syn::makeSyntheticDataset(scenario(true));
  const FilterRun filter_like = perturbedRun(noisy, 0.1, 2.0);
  const Errors one = errorsAgainstTruth(noisy, smoothRun(noisy, filter_like, RunSmootherOptions{}));
  const Errors chunked = errorsAgainstTruth(noisy, smoothRun(noisy, filter_like, o));
  EXPECT_LT(chunked.pos_rms_m, 1.5 * one.pos_rms_m + 0.005);
  EXPECT_LT(chunked.anees_p, 6.0);
  EXPECT_GT(chunked.anees_p, 1.0);
  // Each output pose once, in order.
  for (size_t i = 1; i < sm.poses.size(); ++i) EXPECT_LT(sm.poses[i - 1].t, sm.poses[i].t);
  EXPECT_EQ(sm.poses.size(), run.poses.size());
}

TEST(BatchSmoother, HeavyTailedRangesDoNotPullTheTrajectory) {
  Dataset ds = syn::makeSyntheticDataset(scenario(true));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  int n_out = 0;
  for (auto& r : ds.ranges)
    if (u01(rng) < 0.08) {  // NLOS excess: positive, 0.3–3 m
      r.range_m += 0.3 + 2.7 * u01(rng);
      ++n_out;
    }
  ASSERT_GT(n_out, 100);
  const FilterRun run = perturbedRun(ds, 0.1, 2.0);
  // The loss alone: without the NLOS mixture (whatever the estimator's default ε), which would
  // down-weight the long ranges under squared loss too.
  RunSmootherOptions robust;
  robust.nlos_fraction = 0.0;
  const Errors e_robust = errorsAgainstTruth(ds, smoothRun(ds, run, robust));
  RunSmootherOptions squared = robust;  // a Huber loss whose corner no residual reaches: least squares
  squared.solver.range_loss = BatchSmootherOptions::Loss::Huber;
  squared.solver.loss_scale_sigmas = 1e6;
  const Errors e_squared = errorsAgainstTruth(ds, smoothRun(ds, run, squared));
  EXPECT_LT(e_robust.pos_rms_m, 0.04);
  EXPECT_GT(e_squared.pos_rms_m, 2.0 * e_robust.pos_rms_m);
}

TEST(BatchSmoother, TheNlosMixtureTakesOutASmallPositiveExcessTheLossKeeps) {
  // 10 % of the ranges carry an NLOS excess of 0.2–0.6 m (2–6 σ): within the Cauchy loss's reach,
  // so it biases the fit; the mixture's EM over the passes takes those ranges with little weight.
  const Dataset clean = syn::makeSyntheticDataset(scenario(true));
  Dataset ds = clean;
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  int n_nlos = 0;
  for (auto& r : ds.ranges)
    if (u01(rng) < 0.1) {
      r.range_m += 0.2 + 0.4 * u01(rng);
      ++n_nlos;
    }
  ASSERT_GT(n_nlos, 100);
  const FilterRun run = perturbedRun(ds, 0.1, 2.0);
  RunSmootherOptions off, on;
  off.nlos_fraction = 0.0;
  on.nlos_fraction = 0.1;
  const SmoothedRun sm_off = smoothRun(ds, run, off), sm_on = smoothRun(ds, run, on);
  const Errors e_off = errorsAgainstTruth(ds, sm_off), e_on = errorsAgainstTruth(ds, sm_on);
  const Errors e_clean = errorsAgainstTruth(clean, smoothRun(clean, run, off));
  std::cout << "NLOS excess on " << n_nlos << " ranges: position RMSE " << e_off.pos_rms_m << " m (mixture off), "
            << e_on.pos_rms_m << " m (on, " << sm_on.chunks[0].result.n_range_nlos
            << " ranges with w < 0.5); without the excess " << e_clean.pos_rms_m << " m\n";
  EXPECT_EQ(sm_off.chunks[0].result.n_range_nlos, 0);
  EXPECT_GT(sm_on.chunks[0].result.n_range_nlos, n_nlos / 2);  // measured 206 of 232
  // Measured (2026-12-06): 0.0329 m off, 0.0240 m on, 0.0232 m without the excess: the mixture
  // takes back 92 % of what the excess costs. Other draws of the excess (seeds 21, 34, 55): off
  // 0.040 / 0.037 / 0.036 m, on 0.031 / 0.025 / 0.028 m.
  EXPECT_LT(e_on.pos_rms_m, 0.85 * e_off.pos_rms_m);
  EXPECT_LT(e_on.pos_rms_m - e_clean.pos_rms_m, 0.3 * (e_off.pos_rms_m - e_clean.pos_rms_m));
  // Unset, ε is the estimator's (uwb.nlos_fraction of its options): the same fit as when given.
  RunSmootherOptions estimator_eps;
  estimator_eps.nlos_fraction = estimator::EstimatorOptions{}.uwb.nlos_fraction;
  const SmoothedRun sm_default = smoothRun(ds, run, RunSmootherOptions{});
  const SmoothedRun sm_given = smoothRun(ds, run, estimator_eps);
  ASSERT_EQ(sm_default.poses.size(), sm_given.poses.size());
  for (size_t i = 0; i < sm_default.poses.size(); ++i)
    ASSERT_EQ(sm_default.poses[i].p_IinG, sm_given.poses[i].p_IinG) << "pose " << i;
}

TEST(BatchSmoother, TheCovarianceIsConsistentOnNoisyData) {
  const Dataset ds = syn::makeSyntheticDataset(scenario(true));
  const Errors e = errorsAgainstTruth(ds, smoothRun(ds, perturbedRun(ds, 0.1, 2.0), RunSmootherOptions{}));
  EXPECT_LT(e.pos_rms_m, 0.05);
  // 3 if consistent; one 30 s trajectory's errors are correlated in time, so allow a wide band.
  EXPECT_GT(e.anees_p, 1.0);
  EXPECT_LT(e.anees_p, 6.0);
  EXPECT_GT(e.anees_theta, 0.5);
  EXPECT_LT(e.anees_theta, 6.0);
}

TEST(BatchSmoother, FindsGravityAlongPlusZInAnAnchorFrameWithZDown) {
  Dataset ds = syn::makeSyntheticDataset(scenario(false));
  // The same scene in a frame turned 180° about x: gravity along +z of it.
  const Eigen::Matrix3d F = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  for (auto& [id, p] : ds.setup.abs_anchor_positions) p = F * p;
  for (auto& g : ds.ground_truth) {
    g.p_IinG = F * g.p_IinG;
    g.q_ItoG = Eigen::Quaterniond(F * g.q_ItoG.toRotationMatrix());
  }
  const SmoothedRun sm = smoothRun(ds, perturbedRun(ds, 0.2, 3.0), RunSmootherOptions{});
  EXPECT_EQ(sm.chunks[0].gravity_z_sign, 1.0);
  expectExact(ds, sm);
}

TEST(BatchSmoother, StartsFromTheGyroBeforeTheFiltersLastReinitialization) {
  const Dataset ds = syn::makeSyntheticDataset(scenario(false));
  FilterRun run = perturbedRun(ds, 0.1, 1.0);
  // Until 15 s the filter's attitude was upside down (the wrong gravity), then it re-initialized.
  const Eigen::Matrix3d flip = expMap(Eigen::Vector3d(M_PI, 0.0, 0.0));
  for (auto& p : run.poses)
    if (p.t.sec() < 15.0) p.q_ItoG = Eigen::Quaterniond(flip * p.q_ItoG.toRotationMatrix());
  const SmoothedRun sm = smoothRun(ds, run, RunSmootherOptions{});
  EXPECT_EQ(sm.chunks[0].reinit_jumps, 1);
  expectExact(ds, sm);
}

TEST(BatchSmoother, RefusesARunWithoutPosesAndAProblemWithoutIMU) {
  const Dataset ds = syn::makeSyntheticDataset(scenario(false));
  EXPECT_THROW(smoothRun(ds, FilterRun{}, RunSmootherOptions{}), std::runtime_error);
  Dataset no_imu = ds;
  no_imu.imu.clear();
  EXPECT_THROW(smoothRun(no_imu, perturbedRun(ds, 0.1, 1.0), RunSmootherOptions{}), std::runtime_error);
}

TEST(BatchSmoother, EstimatesAnUncertainAnchorWithTheTrajectory) {
  syn::SyntheticOptions o = scenario(false);
  o.n_estimated_anchors = 1;   // 106, given in setup.yaml with a σ
  o.anchor_to_anchor = true;   // the mesh: 106 ranges to the known anchors too
  Dataset ds = syn::makeSyntheticDataset(o);
  const Eigen::Vector3d p_true = ds.setup.abs_anchor_positions.at(106);
  ds.setup.abs_anchor_positions[106] = p_true + Eigen::Vector3d(0.3, -0.2, 0.1);  // a poor guess
  ds.setup.abs_anchor_sigmas_m[106] = 0.5;
  const FilterRun run = perturbedRun(ds, 0.05, 1.0);
  const SmoothedRun sm = smoothRun(ds, run, RunSmootherOptions{});  // anchors fitted by default
  ASSERT_EQ(sm.anchors.size(), 1u);
  EXPECT_EQ(sm.anchors[0].id, 106);
  EXPECT_LT((sm.anchors[0].p_AinG - p_true).norm(), 0.01);
  EXPECT_TRUE(sm.anchors[0].cov_p_m2.allFinite());
  expectExact(ds, sm);
  // Taken at its guess (its σ in the range noise), the anchor pulls the trajectory.
  RunSmootherOptions keep;
  keep.estimate_anchors = false;
  const Errors e_fixed = errorsAgainstTruth(ds, smoothRun(ds, run, keep));
  EXPECT_GT(e_fixed.pos_rms_m, 0.02);
}

TEST(BatchSmoother, AnImuGapIsBridgedByItsNoiseModel) {
  Dataset ds = syn::makeSyntheticDataset(scenario(false));
  // No IMU samples for 1.5 s in flight: the increments across run on readings interpolated over it.
  std::erase_if(ds.imu, [](const ImuSample& s) { return s.t.sec() > 12.0 && s.t.sec() < 13.5; });
  const FilterRun run = perturbedRun(ds, 0.05, 1.0);
  const SmoothedRun sm = smoothRun(ds, run, RunSmootherOptions{});
  EXPECT_EQ(sm.chunks[0].imu_gaps, 1);
  // Scored over the gap: the ranges hold the pose, the gap's increments count little (measured
  // 0.009 m; 0.035 m when the interpolated readings are trusted as sensor readings).
  Dataset gap = ds;
  std::erase_if(gap.ground_truth, [](const PoseSample& p) { return p.t.sec() < 11.5 || p.t.sec() > 14.0; });
  const Errors e = errorsAgainstTruth(gap, sm);
  EXPECT_LT(e.pos_rms_m, 0.02);
  // Noisy data: the covariance over the gap covers the error (ANEES 29 without the gap model).
  Dataset noisy = syn::makeSyntheticDataset(scenario(true));
  std::erase_if(noisy.imu, [](const ImuSample& s) { return s.t.sec() > 12.0 && s.t.sec() < 13.5; });
  const SmoothedRun sn = smoothRun(noisy, perturbedRun(noisy, 0.05, 1.0), RunSmootherOptions{});
  std::erase_if(noisy.ground_truth, [](const PoseSample& p) { return p.t.sec() < 11.5 || p.t.sec() > 14.0; });
  const Errors en = errorsAgainstTruth(noisy, sn);
  EXPECT_LT(en.anees_p, 6.0);
  EXPECT_LT(en.anees_theta, 6.0);
}

TEST(BatchSmoother, ARemainderShorterThanAKnotPeriodJoinsTheLastChunk) {
  const Dataset ds = syn::makeSyntheticDataset(scenario(false));
  const FilterRun run = perturbedRun(ds, 0.0, 0.0);
  RunSmootherOptions o;
  o.overlap_s = 0.0;
  // Chunks end 14.99 s apart: the last 0.02 s of the span would be a chunk of one knot.
  o.chunk_s = 0.5 * ((run.poses.back().t - run.poses.front().t).sec() - 0.02);
  const SmoothedRun sm = smoothRun(ds, run, o);
  EXPECT_EQ(sm.chunks.size(), 2u);
  EXPECT_EQ(sm.poses.size(), run.poses.size());
  expectExact(ds, sm);
}
