#include "calibrator/anchor_calibrator.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "calibrator/calibration_problem.h"
#include "calibrator/nonlinear_refiner.h"
#include "calibrator/optimal_double_solver.h"
#include "calibrator/range_model.h"
#include "calibrator/ransac_solver.h"
#include "calibrator/reference_geometry.h"

namespace meshnav::calib {

namespace {

/// True for every observation whose reference has a slot (is not ignored).
std::vector<bool> usableRanges(const CalibrationProblem& pb) {
  std::vector<bool> use(pb.observations().size());
  for (int i = 0; i < static_cast<int>(use.size()); ++i) use[static_cast<size_t>(i)] = pb.slotOf(i) >= 0;
  return use;
}

/// Prefix of a linear-step failure on coplanar moving references (their rows carry nothing along
/// the plane's normal when the references lie exactly in it).
std::string coplanarNote(const GeometryReport& geo) {
  if (!geo.mirror) return {};
  char buf[160];
  std::snprintf(buf, sizeof buf, "reference positions are coplanar (RMS off their plane %.3f m), ", geo.rms_spread_m(2));
  return buf;
}

/// Evidence of the stationary references for an anchor at p: Σ_r ½ ((z̃_r − β_r‖p − p_R‖ − γ_r)/σ_r)²
/// over the stationary references whose γ has a prior (γ_r, β_r its prior means, z̃_r the median of
/// their ranges, σ_r² = σ_γ² + σ_d²/n_r + uᵀΣ_R u with Σ_R the reference position's covariance, a
/// calibrated anchor's, and u the direction to p): their γ marginalized over its prior. The moving
/// references are left out: mirrored across their plane they fit alike, and what they still tell
/// apart (their small height changes) is the estimated trajectory's error as much as the anchor's.
double stationaryEvidence(const CalibrationProblem& pb, const Eigen::Vector3d& p, double sigma_range_m) {
  double cost = 0.0;
  for (const auto& slot : pb.slots()) {
    if (slot.moving || slot.obs.empty() || !(slot.prior.sigma_gamma_m > 0.0)) continue;
    const Eigen::Vector3d& p_R = slot.p_mean_RinG;
    Eigen::Matrix3d cov_R = Eigen::Matrix3d::Zero();
    std::vector<double> z;
    for (int i : slot.obs) {
      const auto& o = pb.observations()[static_cast<size_t>(i)];
      cov_R += o.cov_p_RinG_m2;
      z.push_back(o.z_m);
    }
    const double n = static_cast<double>(slot.obs.size());
    cov_R /= n;  // one reference position: its uncertainty does not average out
    auto mid = z.begin() + static_cast<long>(z.size() / 2);
    std::nth_element(z.begin(), mid, z.end());
    const Eigen::Vector3d u = (p - p_R).normalized();
    const double var = slot.prior.sigma_gamma_m * slot.prior.sigma_gamma_m + sigma_range_m * sigma_range_m / n +
                       u.dot(cov_R * u);
    const double r = *mid - slot.prior.beta * (p - p_R).norm() - slot.prior.gamma_m;
    cost += 0.5 * r * r / var;
  }
  return cost;
}

/// The side of a mirror plane (coplanar moving references) the anchor is on. `ref` and its mirror
/// image are both refined on every usable range; the side is then decided by the stationary
/// references alone (stationaryEvidence), whose evidence must differ by `mirror_min_cost_gap`.
/// Both refinements landing on one solution far from the plane is no evidence either: the side is
/// then compared against that solution's mirror image. On success `ref` is the chosen side's
/// refinement; else `why` says what is ambiguous.
bool pickMirrorSide(const CalibrationProblem& pb, const NonlinearRefiner& refiner, const MirrorPlane& plane,
                    const CalibratorOptions& options, RefineResult& ref, double& extra_normal_var_m2,
                    std::string& why) {
  extra_normal_var_m2 = 0.0;
  const std::vector<bool> all = usableRanges(pb);
  AnchorParams mirrored = ref.params;
  mirrored.p_AinG = plane.reflect(ref.params.p_AinG);
  const RefineResult a = refiner.refine(pb, ref.params, all);
  const RefineResult b = refiner.refine(pb, mirrored, all);
  if (!a.converged && !b.converged) {
    why = "mirror check: neither side's refinement converged";
    return false;
  }
  const RefineResult& first = a.converged ? a : b;  // the other, b, only when both converged
  const bool distinct = a.converged && b.converged &&
                        (a.params.p_AinG - b.params.p_AinG).norm() >= 2.0 * options.sigma_range_m;
  const Eigen::Vector3d p1 = first.params.p_AinG;
  const Eigen::Vector3d p2 = distinct ? b.params.p_AinG : plane.reflect(p1);
  if ((p1 - p2).norm() < 2.0 * options.sigma_range_m) {  // on the plane: both sides are one solution
    ref.params = first.params;
    ref.iterations += a.iterations + b.iterations;
    return true;
  }
  const double e1 = stationaryEvidence(pb, p1, options.sigma_range_m);
  const double e2 = stationaryEvidence(pb, p2, options.sigma_range_m);
  const bool decided = std::abs(e1 - e2) >= options.mirror_min_cost_gap && (e1 <= e2 || distinct);
  const double d = (p1 - p2).norm();
  if (!decided && d <= options.mirror_merge_max_m) {
    // Undecided but close: the better side, its covariance widened by d² along the normal so that
    // the other side lies within 1σ of it.
    extra_normal_var_m2 = d * d;
  } else if (!decided) {
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "mirror-ambiguous: the moving references span a plane and the stationary ones (up to %.2f m off "
                  "it) do not tell the side of the two %.2f m apart (evidence %.1f and %.1f, gap below %.1f)",
                  plane.reference_offset_m, d, e1, e2, options.mirror_min_cost_gap);
    why = buf;
    return false;
  }
  const int iterations = ref.iterations + a.iterations + b.iterations;
  ref = (e1 <= e2 || !distinct) ? first : b;
  ref.iterations = iterations;
  return true;
}

/// The linear start: RANSAC around the optimal double step (its inliers in `use`), or the step on
/// every usable range. False with `why` when no solution was found.
bool linearStep(const CalibrationProblem& pb, const CalibratorOptions& options, std::vector<bool>& use,
                LinearSolution& lin, int& ransac_iterations, std::string& why) {
  use = usableRanges(pb);
  if (options.ransac) {
    RansacResult rr = RansacSolver(options).run(pb, options.ransac_seed);
    ransac_iterations = rr.iterations;
    if (!rr.ok) {
      why = "RANSAC: " + rr.reason;
      return false;
    }
    use = rr.inliers;
    lin = rr.solution;
    return true;
  }
  lin = OptimalDoubleSolver(options).solve(pb);
  if (!lin.ok) why = "linear step: " + lin.reason;
  return lin.ok;
}

/// A side-decided anchor's covariance: widened along the plane's normal by `extra_var_m2` (an
/// undecided side kept, mirror_merge_max), then refused (false, `why`) when its σ along the normal
/// exceeds `mirror_max_normal_sigma_m`.
bool mirrorCovariance(const MirrorPlane& plane, double extra_var_m2, const CalibratorOptions& options,
                      CovarianceEstimate& cov, std::string& why) {
  const Eigen::Vector3d& n = plane.normal;
  cov.P.block<3, 3>(0, 0) += extra_var_m2 * n * n.transpose();
  const double sigma_n = std::sqrt(std::max(0.0, n.dot(cov.P.block<3, 3>(0, 0) * n)));
  if (sigma_n <= options.mirror_max_normal_sigma_m) return true;
  char buf[200];
  std::snprintf(buf, sizeof buf,
                "reference positions are coplanar and the distance from their plane is weakly fixed (sigma %.2f m "
                "along its normal > %.2f m)",
                sigma_n, options.mirror_max_normal_sigma_m);
  why = buf;
  return false;
}

/// Final inlier test at x: |r_i|/σ_eff,i < k·max(1, s_robust), s_robust = 1.4826·median |r/σ_eff|
/// over the candidate set (so an under-stated σ_d does not turn good ranges into outliers).
std::vector<bool> classifyFinal(const CalibrationProblem& pb, const AnchorParams& x, const std::vector<bool>& candidates,
                                double k) {
  const auto n = pb.observations().size();
  std::vector<double> w(n, 0.0), abs_cand;
  for (int i = 0; i < static_cast<int>(n); ++i) {
    if (pb.slotOf(i) < 0) continue;
    w[static_cast<size_t>(i)] =
        std::abs(pb.observations()[static_cast<size_t>(i)].z_m - predictRange(pb, x, i)) / effectiveSigma(pb, x, i);
    if (candidates.empty() || candidates[static_cast<size_t>(i)]) abs_cand.push_back(w[static_cast<size_t>(i)]);
  }
  double s_rob = 1.0;
  if (!abs_cand.empty()) {
    auto mid = abs_cand.begin() + static_cast<long>(abs_cand.size() / 2);
    std::nth_element(abs_cand.begin(), mid, abs_cand.end());
    s_rob = std::max(1.0, 1.4826 * *mid);
  }
  std::vector<bool> in(n, false);
  for (int i = 0; i < static_cast<int>(n); ++i)
    in[static_cast<size_t>(i)] = pb.slotOf(i) >= 0 && w[static_cast<size_t>(i)] < k * s_rob;
  return in;
}

/// The final inliers `inl` (in the problem's order) mapped back to the caller's order: the problem
/// sorted the observations by time (stable), so the same sort gives the map.
std::vector<bool> inliersInCallerOrder(const std::vector<CalibObservation>& observations, const std::vector<bool>& inl) {
  std::vector<size_t> order(observations.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return observations[a].t < observations[b].t; });
  std::vector<bool> out(observations.size(), false);
  for (size_t k = 0; k < order.size(); ++k) out[order[k]] = inl[k];
  return out;
}

/// γ, β with their σ and the range statistics of each reference (slot) at the solution `x`.
std::vector<ReferenceBiasEstimate> referenceEstimates(const CalibrationProblem& pb, const AnchorParams& x,
                                                      const CovarianceEstimate& cov, const std::vector<bool>& inl,
                                                      double default_sigma_range_m) {
  std::vector<ReferenceBiasEstimate> out;
  for (int s = 0; s < static_cast<int>(pb.slots().size()); ++s) {
    const auto& slot = pb.slots()[static_cast<size_t>(s)];
    ReferenceBiasEstimate r;
    r.ref_id = slot.id;
    r.moving = slot.moving;
    r.beta_estimated = pb.betaIndex(s) >= 0;
    r.gamma_m = x.gamma_m[static_cast<size_t>(s)];
    r.sigma_gamma_m = std::sqrt(cov.P(pb.gammaIndex(s), pb.gammaIndex(s)));
    r.beta = x.beta[static_cast<size_t>(s)];
    r.sigma_beta = r.beta_estimated ? std::sqrt(cov.P(pb.betaIndex(s), pb.betaIndex(s))) : 0.0;
    double sq = 0.0;
    for (int i : slot.obs) {
      if (inl[static_cast<size_t>(i)]) {
        sq += std::pow(pb.observations()[static_cast<size_t>(i)].z_m - predictRange(pb, x, i), 2);
        ++r.n_inliers;
      } else {
        ++r.n_outliers;
      }
    }
    r.sigma_range_m = r.n_inliers > 0 ? std::sqrt(sq / r.n_inliers) : default_sigma_range_m;
    out.push_back(r);
  }
  return out;
}

/// The [p, γ_0..γ_n-1] block of the stacked covariance, in the order of the references, symmetrized.
Eigen::MatrixXd positionGammaCovariance(const CalibrationProblem& pb, const CovarianceEstimate& cov) {
  const auto ns = static_cast<Eigen::Index>(pb.slots().size());
  std::vector<Eigen::Index> idx = {0, 1, 2};
  for (int s = 0; s < static_cast<int>(ns); ++s) idx.push_back(pb.gammaIndex(s));
  Eigen::MatrixXd out(3 + ns, 3 + ns);
  for (Eigen::Index r = 0; r < 3 + ns; ++r)
    for (Eigen::Index c = 0; c < 3 + ns; ++c)
      out(r, c) = 0.5 * (cov.P(idx[static_cast<size_t>(r)], idx[static_cast<size_t>(c)]) +
                         cov.P(idx[static_cast<size_t>(c)], idx[static_cast<size_t>(r)]));
  return out;
}

}  // namespace

const char* toString(CalibrationStatus s) {
  switch (s) {
    case CalibrationStatus::Ok: return "ok";
    case CalibrationStatus::TooFewMeasurements: return "too_few_measurements";
    case CalibrationStatus::TooFewReferencePositions: return "too_few_reference_positions";
    case CalibrationStatus::DegenerateGeometry: return "degenerate_geometry";
    case CalibrationStatus::IllConditioned: return "ill_conditioned";
  }
  return "?";
}

AnchorInit CalibrationResult::toAnchorInit() const {
  AnchorInit a;
  a.t = t;
  a.id = anchor_id;
  a.p_AinG = p_AinG;
  a.cov_p_m2 = cov_p_m2;
  a.n_inliers = n_inliers;
  a.n_outliers = n_outliers;
  const auto n = static_cast<Eigen::Index>(references.size());
  if (cov_p_gamma_m2.rows() == 3 + n && cov_p_gamma_m2.cols() == 3 + n) {
    a.cov_gamma_p_m2 = cov_p_gamma_m2.bottomLeftCorner(n, 3);
    a.cov_gamma_m2 = cov_p_gamma_m2.bottomRightCorner(n, n);
  }
  for (const auto& r : references) {
    PairBias b;
    b.a = r.ref_id;
    b.b = anchor_id;
    b.gamma_m = r.gamma_m;
    b.beta = r.beta;
    b.sigma_m = r.sigma_range_m;
    b.sigma_gamma_m = r.sigma_gamma_m;
    b.sigma_beta = r.sigma_beta;
    a.biases.push_back(b);
  }
  return a;
}

CalibrationResult AnchorCalibrator::calibrate(SensorId anchor_id, const std::vector<CalibObservation>& observations,
                                              const std::map<SensorId, ReferencePrior>& priors, Timestamp t) const {
  CalibrationResult res;
  res.anchor_id = anchor_id;
  res.t = t;
  res.n_observations = static_cast<int>(observations.size());
  const CalibrationProblem pb(anchor_id, observations, priors, options_);
  auto refuse = [&](CalibrationStatus st, const std::string& why) {
    res.status = st;
    res.reason = why;
    res.inliers.assign(observations.size(), false);
    return res;
  };

  const GeometryReport geo = checkReferenceGeometry(pb, options_);
  if (geo.status != CalibrationStatus::Ok) return refuse(geo.status, geo.reason);

  // 1. Linear step, on RANSAC inliers or on everything.
  std::vector<bool> use;
  LinearSolution lin;
  std::string linear_failure;
  if (!linearStep(pb, options_, use, lin, res.ransac_iterations, linear_failure))
    return refuse(CalibrationStatus::DegenerateGeometry, coplanarNote(geo) + linear_failure);
  res.p_AinG_linear = lin.params.p_AinG;

  // 2. Refinement; with RANSAC a second round on the inliers of the refined model.
  const NonlinearRefiner refiner(options_);
  RefineResult ref = refiner.refine(pb, lin.params, use);
  if (!ref.converged) return refuse(CalibrationStatus::IllConditioned, "refinement failed: " + ref.message);
  double extra_normal_var_m2 = 0.0;
  if (geo.mirror) {
    std::string why;
    if (!pickMirrorSide(pb, refiner, *geo.mirror, options_, ref, extra_normal_var_m2, why))
      return refuse(CalibrationStatus::DegenerateGeometry, why);
  }
  res.lm_iterations = ref.iterations;
  std::vector<bool> inl = classifyFinal(pb, ref.params, {}, options_.outlier_threshold_sigmas);
  if (options_.ransac && inl != use) {
    RefineResult ref2 = refiner.refine(pb, ref.params, inl);
    if (ref2.converged) {
      ref = ref2;
      res.lm_iterations += ref2.iterations;
      inl = classifyFinal(pb, ref.params, {}, options_.outlier_threshold_sigmas);
    }
  }
  const AnchorParams& x = ref.params;

  // 3. Covariance on the final inliers.
  CovarianceEstimate cov = estimateCovariance(pb, x, inl, options_.scale_covariance_by_residuals,
                                              options_.correlated_reference_fraction);
  if (!cov.ok) return refuse(CalibrationStatus::IllConditioned, "information matrix is singular");
  if (std::string why; geo.mirror && !mirrorCovariance(*geo.mirror, extra_normal_var_m2, options_, cov, why))
    return refuse(CalibrationStatus::IllConditioned, why);
  const Eigen::Matrix3d Pp = cov.P.block<3, 3>(0, 0);
  const double sig_max = std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(Pp).eigenvalues()(2)));
  if (!(sig_max <= options_.max_position_sigma_m)) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "position sigma %.2f m exceeds %.2f m", sig_max, options_.max_position_sigma_m);
    return refuse(CalibrationStatus::IllConditioned, buf);
  }

  res.status = CalibrationStatus::Ok;
  res.p_AinG = x.p_AinG;
  res.cov_p_m2 = 0.5 * (Pp + Pp.transpose());
  res.residual_variance_factor = cov.s2;
  res.inliers = inliersInCallerOrder(observations, inl);
  res.references = referenceEstimates(pb, x, cov, inl, options_.sigma_range_m);
  for (const ReferenceBiasEstimate& r : res.references) {
    res.n_inliers += r.n_inliers;
    res.n_outliers += r.n_outliers;
  }
  res.cov_p_gamma_m2 = positionGammaCovariance(pb, cov);
  return res;
}

}  // namespace meshnav::calib
