/// @file motion_aligner_fit.cpp
/// @brief MotionAligner, second part: the fit of the window. Start points over yaw, Levenberg–
/// Marquardt with Huber weights and bias priors, the robust variance factor, and the covariance,
/// end state and acceptance checks of the best fit. The window and the observation model are in
/// motion_aligner.cpp.

#include <Eigen/Dense>
#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "estimator/core/huber.h"
#include "estimator/core/so3.h"
#include "estimator/init/motion_aligner.h"
#include "estimator/init/motion_aligner_internals.h"

namespace meshnav::estimator {

namespace {

using motion_aligner_internal::kBh;
using motion_aligner_internal::kDim;
using motion_aligner_internal::MatU;
using motion_aligner_internal::VecU;

constexpr double kDeg = M_PI / 180.0;

Eigen::Matrix3d rotZ(double yaw) { return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }

/// Two end states are different answers: > 0.5 m apart or > 15° apart in yaw.
bool distinctPoses(const ImuState& a, const ImuState& b) {
  const double dyaw = so3::yawDifference(so3::yawOf(a.q_ItoG), so3::yawOf(b.q_ItoG));
  return (a.p_IinG - b.p_IinG).norm() > 0.5 || std::abs(dyaw) > 15.0 * kDeg;
}

/// The order in which the rivals of the best candidate (cands[0], sorted by cost) are refitted:
/// first the best of those elsewhere (> 0.5 m from `p_best`: a mirror image across nearly coplanar
/// anchors), then by first-pass cost. The first-pass order includes the outliers, so the closest
/// rival need not come first, and a handful of heading variants at the same place must not crowd
/// out the mirror image (a walk under three anchors was initialized 1.15 m below the truth that way).
template <class Candidate>
std::vector<size_t> rivalOrder(const std::vector<Candidate>& cands, const Eigen::Vector3d& p_best) {
  std::vector<size_t> order;
  for (size_t k = 1; k < cands.size(); ++k)
    if ((cands[k].end.p_IinG - p_best).norm() > 0.5) {
      order.push_back(k);
      break;
    }
  for (size_t k = 1; k < cands.size(); ++k)
    if (order.empty() || order.front() != k) order.push_back(k);
  return order;
}

}  // namespace

double MotionAligner::fit(const std::vector<Obs>& obs, const std::vector<HeightObs>& heights,
                          const Eigen::Vector3d& dbg_prior_mean, Unknowns& x,
                          MatU* info) const {
  const double prior_ba = 1.0 / (options_.sigma_bias_acc_m_s2 * options_.sigma_bias_acc_m_s2);
  const double prior_bg = 1.0 / (options_.sigma_bias_gyro_rad_s * options_.sigma_bias_gyro_rad_s);
  const double prior_bh = 1.0 / (options_.sigma_bias_height_m * options_.sigma_bias_height_m);
  auto cost = [&](const Unknowns& u) {
    double c = prior_ba * u.ba.squaredNorm() + prior_bg * (u.dbg - dbg_prior_mean).squaredNorm() + prior_bh * u.bh * u.bh;
    for (const Obs& o : obs)
      if (o.use) c += huber::cost(residual(o, u) / o.r.sigma_m);
    for (const HeightObs& o : heights)
      if (o.use) c += huber::cost(residual(o, u) / o.h.sigma_m);
    return c;
  };
  double c = cost(x), lambda = 1e-3;
  MatU H;
  Eigen::Matrix<double, 1, 16> J;
  // H = Σ w Jᵀ J in its lower triangle only (what LDLT reads; symmetric at the end).
  auto accumulate = [&](double w, double r, VecU& g) {
    for (int i = 0; i < kDim; ++i) {
      const double wj = w * J(i);
      for (int k = 0; k <= i; ++k) H(i, k) += wj * J(k);
      g(i) += wj * r;
    }
  };
  for (int it = 0; it < 25; ++it) {
    H.setZero();
    VecU g = VecU::Zero();
    for (const Obs& o : obs) {
      if (!o.use) continue;
      const double r = residual(o, x, &J);
      const double e = std::abs(r) / o.r.sigma_m;
      accumulate(huber::weight(e) / (o.r.sigma_m * o.r.sigma_m), r, g);
    }
    for (const HeightObs& o : heights) {
      if (!o.use) continue;
      const double r = residual(o, x, &J);
      accumulate(huber::weight(std::abs(r) / o.h.sigma_m) / (o.h.sigma_m * o.h.sigma_m), r, g);
    }
    H.triangularView<Eigen::StrictlyUpper>() = H.transpose();
    H(kBh, kBh) += prior_bh;
    g(kBh) += prior_bh * x.bh;
    H.block<3, 3>(9, 9).diagonal().array() += prior_ba;
    g.segment<3>(9) += prior_ba * x.ba;
    H.block<3, 3>(12, 12).diagonal().array() += prior_bg;
    g.segment<3>(12) += prior_bg * (x.dbg - dbg_prior_mean);
    bool improved = false;
    for (int tries = 0; tries < 6 && !improved; ++tries) {
      MatU A = H;
      A.diagonal() += lambda * H.diagonal().cwiseMax(1e-9);
      const VecU step = -A.ldlt().solve(g);
      const Unknowns xn = x.plus(step);
      const double cn = cost(xn);
      if (std::isfinite(cn) && cn < c) {
        improved = true;
        const bool small = step.norm() < 1e-7 || c - cn < 1e-9 * (1.0 + c);
        x = xn;
        c = cn;
        lambda = std::max(lambda / 4.0, 1e-9);
        if (small) it = 1000;
      } else {
        lambda *= 8.0;
      }
    }
    if (!improved) break;
  }
  if (info) *info = H;
  return c;
}

ImuState MotionAligner::endState(const Unknowns& x, const Increments& end, const Eigen::Vector3d& bias_gyro) const {
  const Eigen::Vector3d g = gravityG();
  const double T = end.tau_s;
  ImuState s;
  s.p_IinG = x.p0 + x.v0 * T + 0.5 * g * T * T + x.R0 * (end.S + end.JS * x.dbg - end.M * x.ba);
  s.v_IinG = x.v0 + g * T + x.R0 * (end.V + end.JV * x.dbg - end.N * x.ba);
  s.q_ItoG = Eigen::Quaterniond(x.R0 * end.C * so3::expMap(end.JC * x.dbg)).normalized();
  s.bias_gyro_rad_s = bias_gyro + x.dbg;
  s.bias_acc_m_s2 = x.ba;
  return s;
}

std::vector<MotionAligner::Unknowns> MotionAligner::starts(const std::vector<Obs>& obs, const Increments& end) const {
  std::map<SensorId, Eigen::Vector3d> anchors;
  for (const Obs& o : obs) anchors[o.r.anchor] = o.r.p_AinG;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& [id, p] : anchors) centroid += p;
  centroid /= static_cast<double>(anchors.size());
  // Static position fit (the window's mean position), multi-start.
  auto staticCost = [&](const Eigen::Vector3d& p) {
    double c = 0.0;
    for (const Obs& o : obs) c += huber::cost((o.r.d_m - (o.r.p_AinG - p).norm()) / o.r.sigma_m);
    return c;
  };
  auto staticFit = [&](Eigen::Vector3d p) {
    for (int it = 0; it < 20; ++it) {
      Eigen::Matrix3d A = Eigen::Matrix3d::Identity() * 1e-6;
      Eigen::Vector3d b = Eigen::Vector3d::Zero();
      for (const Obs& o : obs) {
        const Eigen::Vector3d d = o.r.p_AinG - p;
        const double n = std::max(d.norm(), 1e-6);
        const Eigen::Vector3d J = d / n;  // ∂r/∂p
        const double r = o.r.d_m - n;
        A += J * J.transpose();
        b += J * r;
      }
      p -= A.ldlt().solve(b);
    }
    return p;
  };
  Eigen::Vector3d best = centroid;
  double best_c = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& off : {Eigen::Vector3d(0, 0, -1.5), Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(-2, 0, 0),
                                     Eigen::Vector3d(0, 2, 0), Eigen::Vector3d(0, -2, 0), Eigen::Vector3d(0, 0, 1.5)}) {
    const Eigen::Vector3d p = staticFit(centroid + off);
    const double c = staticCost(p);
    if (p.allFinite() && c < best_c) best_c = c, best = p;
  }
  std::vector<Eigen::Vector3d> positions{best};
  // Nearly coplanar anchors: the mirror image across their plane fits the ranges as well.
  Eigen::MatrixXd D(3, anchors.size());
  int i = 0;
  for (const auto& [id, p] : anchors) D.col(i++) = p - centroid;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(D, Eigen::ComputeFullU);
  if (svd.singularValues()(2) / std::sqrt(static_cast<double>(anchors.size())) < 0.3) {
    const Eigen::Vector3d n = svd.matrixU().col(2);
    positions.push_back(best - 2.0 * n.dot(best - centroid) * n);
  }
  // Roll and pitch of R₀, two ways. (a) The mean raw specific force: gravity dominates it over a
  // few seconds, but each reading is in its own body frame, so a rig tilted one way and then
  // another (a hand-held walk) averages to a level it never had. (b) The specific force integrated
  // in the first sample's body frame, V(T) = ∫ C f ds: R₀ V(T)/T = Δv/T − g exactly, so V(T)
  // levels R₀ to within |Δv|/(gT) whatever the rig did (ISAS-Walk1's first window: the +z fits
  // from (a) ended 200 m off or in local minima, from (b) they decide +z by a margin of 16).
  // Both sets of starts when the two levels differ by more than kLevelBasin_rad, on windows of
  // the full nominal length `window_s` only: on MILUV's longer sparse windows extra starts found
  // lower-cost wrong poses (ifo001 2.46 → 4.28 m), and on shorter ones (the first tries after
  // the start) they found rivals that made one tag's 6 s windows ambiguous
  // (MotionAligner.AHeadingPriorTheFitContradictsIsNotTaken).
  auto levelling = [](const Eigen::Vector3d& f) -> Eigen::Matrix3d {
    const double roll = std::atan2(f.y(), f.z()), pitch = std::atan2(-f.x(), std::hypot(f.y(), f.z()));
    return (Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
        .toRotationMatrix();
  };
  Eigen::Vector3d f = Eigen::Vector3d::Zero();
  const Timestamp t0 = windowStart();
  for (const ImuSample& s : imu_)
    if (s.t >= t0) f += s.acc_m_s2;
  std::vector<Eigen::Matrix3d> levels{levelling(f)};
  const bool nominal_window = std::abs(spanSeconds() - options_.window_s) <= 0.1;
  if (nominal_window && end.V.norm() > 0.0 && f.norm() > 0.0 &&
      std::acos(std::clamp(end.V.normalized().dot(f.normalized()), -1.0, 1.0)) > kLevelBasin_rad)
    levels.push_back(levelling(end.V));
  // Gravity along +z of G: the specific force at rest points along −z, half a turn about x.
  const Eigen::Matrix3d R_up = gravity_z_sign_ > 0.0
                                   ? Eigen::Matrix3d(Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal())
                                   : Eigen::Matrix3d::Identity();
  std::vector<Unknowns> out;
  for (const Eigen::Matrix3d& R_rp : levels)
    for (const Eigen::Vector3d& p : positions)
      for (int k = 0; k < options_.yaw_starts; ++k) {
        Unknowns x;
        x.p0 = p;
        x.R0 = rotZ(2.0 * M_PI * k / options_.yaw_starts) * R_up * R_rp;
        out.push_back(x);
      }
  return out;
}

bool MotionAligner::fitStarts(const Eigen::Vector3d& bias_gyro_rad_s, Window* w) {
  // The increments are linear in δb_ω about the bias they were integrated with, b_lin; a large
  // correction (a consumer gyro's 0.02 rad/s over 12 s: 14°) leaves second-order errors of metres
  // in the predicted positions, and the fit then has no minimum at the truth (sweep seed 5 run181:
  // a hover initialized 1.2 m below it). Integrate again at the best fit's bias and refit; the
  // prior stays centred on the caller's bias.
  // Only on a window of the nominal length (`window_s`, dense ranges). On a window reaching back
  // for sparse ranges (MILUV, one range per 1.2 s) it let ifo002 start 27 s earlier from a right
  // pose that the filter could not hold with those ranges; the long lost stretch after it drifted
  // 166 m (ATE 3.3 → 54 m). Off there until a lost filter's drift is bounded (docs/robustness.md).
  const bool relinearize = options_.relinearize_rad > 0.0 && spanSeconds() <= options_.window_s + 1e-6;
  // Windows 0.5 s apart share most of their data: start at the gyro bias the previous solve
  // fitted about the same prior, so that repeated solves (while refused) need fewer passes.
  w->b_lin = relinearize && last_fit_ && last_fit_->first == bias_gyro_rad_s ? last_fit_->second : bias_gyro_rad_s;
  for (int pass = 0;; ++pass) {
    w->dbg_prior_mean = bias_gyro_rad_s - w->b_lin;
    w->obs = buildObservations(w->b_lin, &w->end, &w->heights);
    std::set<SensorId> anchor_ids;
    for (const Obs& o : w->obs) anchor_ids.insert(o.r.anchor);
    if (static_cast<int>(w->obs.size()) < options_.min_ranges ||
        static_cast<int>(anchor_ids.size()) < options_.min_anchors) {
      reason_ = "motion alignment: " + std::to_string(w->obs.size()) + " tag ranges to " +
                std::to_string(anchor_ids.size()) + " known anchors in the window, need " +
                std::to_string(options_.min_ranges) + " to " + std::to_string(options_.min_anchors);
      return false;
    }
    w->cands.clear();
    for (Unknowns x : starts(w->obs, w->end)) {  // δb_ω = 0: at b_lin
      const double c = fit(w->obs, w->heights, w->dbg_prior_mean, x, nullptr);
      if (std::isfinite(c)) w->cands.push_back({x, c, endState(x, w->end, w->b_lin)});
    }
    if (w->cands.empty()) {
      reason_ = "motion alignment: no fit converged";
      return false;
    }
    std::sort(w->cands.begin(), w->cands.end(), [](const Candidate& a, const Candidate& b) { return a.cost < b.cost; });
    if (relinearize) last_fit_ = std::make_pair(bias_gyro_rad_s, Eigen::Vector3d(w->b_lin + w->cands.front().x.dbg));
    const double turned_rad = w->cands.front().x.dbg.norm() * w->end.tau_s;
    if (!relinearize || turned_rad <= options_.relinearize_rad ||
        pass >= options_.max_relinearizations)
      return true;
    w->b_lin += w->cands.front().x.dbg;
    ++relinearizations_;
  }
}

std::optional<AlignmentResult> MotionAligner::solve(const Eigen::Vector3d& bias_gyro_rad_s,
                                                    const std::optional<HeadingPrior>& heading) {
  if (spanSeconds() < options_.min_span_s) {
    reason_ = "motion alignment: " + std::to_string(spanSeconds()) + " s of IMU data, need " +
              std::to_string(options_.min_span_s) + " s";
    return std::nullopt;
  }
  // Multi-start, then keep the distinct local minima.
  Window w;
  if (!fitStarts(bias_gyro_rad_s, &w)) return std::nullopt;
  if (options_.flight_volume) {  // outside the volume the vehicle stays in: not a pose at all
    const FlightVolume& v = *options_.flight_volume;
    std::erase_if(w.cands, [&](const Candidate& c) { return v.distanceOutside(c.end.p_IinG) > options_.volume_margin_m; });
    if (w.cands.empty()) {
      reason_ = "motion alignment: every fit of the window ends outside the flight volume";
      return std::nullopt;
    }
  }
  std::vector<Obs>& obs = w.obs;
  std::vector<HeightObs>& heights = w.heights;
  const Increments& end = w.end;
  const Eigen::Vector3d& b_lin = w.b_lin;
  const std::vector<Candidate>& cands = w.cands;
  // Outliers by the best candidate, then refit the best and the best distinct rival on the inliers.
  Unknowns best = cands.front().x;
  for (Obs& o : obs) o.use = std::abs(residual(o, best)) <= std::max(options_.outlier_m, 4.0 * o.r.sigma_m);
  for (HeightObs& o : heights) o.use = std::abs(residual(o, best)) <= std::max(0.3, 4.0 * o.h.sigma_m);
  MatU info;
  const double best_cost = fit(obs, heights, w.dbg_prior_mean, best, &info);
  const ImuState best_end = endState(best, end, b_lin);
  // Distinct rivals are refitted on the same inliers, in rivalOrder, up to 6 in all.
  // Costs are compared in units of the residuals' own scatter: ranges that fit worse than their σ
  // (unmodelled drift over the window, heavier noise) make a cost difference mean less.
  const double v = robustVarianceFactor(obs, best);
  const double margin = options_.ambiguity_chi2 * v;
  // The heading term of a minimum's score, in the cost's units (solve's contract); 0 without a prior.
  auto headingTerm = [&](const ImuState& e) {
    if (!heading) return 0.0;
    const double d = so3::yawDifference(so3::yawOf(e.q_ItoG), heading->yaw_rad);
    return v * d * d / heading->var_rad2;
  };
  auto ambiguity = [&](const ImuState& a, const ImuState& b, double dcost) {
    const double dyaw = so3::yawDifference(so3::yawOf(a.q_ItoG), so3::yawOf(b.q_ItoG)) / kDeg;
    return "motion alignment: ambiguous (two poses " + fmt::format("{:.2f} m and {:.1f} deg", (a.p_IinG - b.p_IinG).norm(),
                                                                   std::abs(dyaw)) +
           " apart score within " + fmt::format("{:.1f} (margin {:.1f}{})", dcost, margin,
                                                heading ? ", with the heading prior" : ", ranges only") +
           "): anchor geometry or motion cannot fix the pose yet";
  };
  struct Minimum {
    Unknowns x;
    ImuState e;
    double score;
  };
  std::vector<Minimum> minima{{best, best_end, best_cost + headingTerm(best_end)}};
  bool ranges_ambiguous = false;  // a distinct minimum fits within the margin by the ranges alone
  std::vector<ImuState> checked;
  for (const size_t k : rivalOrder(cands, best_end.p_IinG)) {
    if (checked.size() >= 6) break;
    if (!distinctPoses(cands[k].end, best_end)) continue;
    if (std::any_of(checked.begin(), checked.end(), [&](const ImuState& c) { return !distinctPoses(cands[k].end, c); }))
      continue;
    checked.push_back(cands[k].end);
    Unknowns rival = cands[k].x;
    const double c = fit(obs, heights, w.dbg_prior_mean, rival, nullptr);
    const ImuState rival_end = endState(rival, end, b_lin);
    if (!distinctPoses(rival_end, best_end)) continue;
    if (c - best_cost < margin) {
      if (!heading) {
        reason_ = ambiguity(rival_end, best_end, c - best_cost);
        return std::nullopt;
      }
      ranges_ambiguous = true;
    }
    minima.push_back({rival, rival_end, c + headingTerm(rival_end)});
  }
  // The prior decides only what the ranges leave open: an unambiguous fit is taken by its cost.
  if (heading && ranges_ambiguous) {
    // The lowest score, unless another distinct minimum scores within the margin of it.
    std::sort(minima.begin(), minima.end(), [](const Minimum& a, const Minimum& b) { return a.score < b.score; });
    for (size_t k = 1; k < minima.size(); ++k)
      if (minima[k].score - minima[0].score < margin && distinctPoses(minima[k].e, minima[0].e)) {
        reason_ = ambiguity(minima[k].e, minima[0].e, minima[k].score - minima[0].score);
        return std::nullopt;
      }
    if (distinctPoses(minima[0].e, best_end)) {  // a rival won: its covariance from its own fit
      best = minima[0].x;
      fit(obs, heights, w.dbg_prior_mean, best, &info);
      ++heading_decisions_;
    }
  }
  return finish(obs, heights, best, info, end, b_lin, heading);
}

std::optional<MotionAligner::GravityCheck> MotionAligner::checkGravityDirection(const Eigen::Vector3d& bias_gyro_rad_s) {
  if (spanSeconds() < options_.min_span_s) {
    reason_ = "gravity check: too short a window";
    return std::nullopt;
  }
  Increments end;
  std::vector<HeightObs> heights;
  std::vector<Obs> obs = buildObservations(bias_gyro_rad_s, &end, &heights);
  if (!heights.empty()) {
    reason_ = "gravity check: heights are in the window (their floor is below, along −z)";
    return std::nullopt;
  }
  if (static_cast<int>(obs.size()) < options_.min_ranges) {
    reason_ = "gravity check: " + std::to_string(obs.size()) + " ranges in the window";
    return std::nullopt;
  }
  GravityCheck check;
  check.n_ranges = static_cast<int>(obs.size());
  Unknowns best_up;
  for (const double sign : {-1.0, 1.0}) {
    gravity_z_sign_ = sign;
    double best = std::numeric_limits<double>::infinity();
    for (Unknowns x : starts(obs, end)) {
      const double c = fit(obs, heights, Eigen::Vector3d::Zero(), x, nullptr);
      if (std::isfinite(c) && c < best) {
        best = c;
        if (sign < 0.0) best_up = x;
      }
    }
    (sign < 0.0 ? check.cost_z_up : check.cost_z_down) = best;
  }
  gravity_z_sign_ = assumed_gravity_z_sign_;
  if (!std::isfinite(check.cost_z_up) || !std::isfinite(check.cost_z_down)) {
    reason_ = "gravity check: no fit converged";
    return std::nullopt;
  }
  check.margin = options_.ambiguity_chi2 * robustVarianceFactor(obs, best_up);
  return check;
}

double MotionAligner::robustVarianceFactor(const std::vector<Obs>& obs, const Unknowns& x) const {
  std::vector<double> abs_e;
  for (const Obs& o : obs)
    if (o.use) abs_e.push_back(std::abs(residual(o, x)) / o.r.sigma_m);
  return huber::varianceFactor(std::move(abs_e));
}

std::optional<AlignmentResult> MotionAligner::finish(const std::vector<Obs>& obs, const std::vector<HeightObs>& heights,
                                                     const Unknowns& x, const MatU& info, const Increments& end,
                                                     const Eigen::Vector3d& bias_gyro,
                                                     const std::optional<HeadingPrior>& heading) {
  const MatU Sigma = options_.cov_inflation * info.ldlt().solve(MatU::Identity());
  const ImuState e0 = endState(x, end, bias_gyro);
  Eigen::Matrix<double, 15, kDim> J;
  for (int j = 0; j < kDim; ++j) {
    VecU d = VecU::Zero();
    d(j) = 1e-6;
    J.col(j) = (endState(x.plus(d), end, bias_gyro).boxminus(e0) - endState(x.plus(-d), end, bias_gyro).boxminus(e0)) / 2e-6;
  }
  AlignmentResult res;
  res.imu = e0;
  res.cov = J * Sigma * J.transpose();
  res.cov = (0.5 * (res.cov + res.cov.transpose())).eval();
  for (int i = 0; i < 3; ++i) {  // floors: the fit's model is not exact
    res.cov(ImuErr::kP + i, ImuErr::kP + i) += 0.02 * 0.02;
    res.cov(ImuErr::kV + i, ImuErr::kV + i) += 0.05 * 0.05;
    res.cov(ImuErr::kTheta + i, ImuErr::kTheta + i) += std::pow(0.5 * kDeg, 2);
  }
  if (heading) {
    Eigen::Matrix<double, 15, 1> h = Eigen::Matrix<double, 15, 1>::Zero();
    h.segment<3>(ImuErr::kTheta) = so3::yawDirection(res.imu.q_ItoG);  // δψ = nᵀ δθ
    const Eigen::Matrix<double, 15, 1> Ph = res.cov * h;
    const double s = h.dot(Ph) + heading->var_rad2;
    const double r = so3::yawDifference(heading->yaw_rad, so3::yawOf(res.imu.q_ItoG));
    // A prior the fit contradicts (r²/s beyond the ambiguity bound, χ²₁) is the lost filter's
    // error, not information: the pose keeps the fit's own heading.
    if (r * r / s <= options_.ambiguity_chi2) {
      const Eigen::Matrix<double, 15, 1> K = Ph / s;
      res.imu.boxplus(K * r);
      res.cov -= K * Ph.transpose();
      res.cov = (0.5 * (res.cov + res.cov.transpose())).eval();
    } else {
      ++heading_prior_rejections_;
    }
  }
  res.t = imu_.back().t;
  res.last_imu = imu_.back();
  res.window_s = spanSeconds();
  res.height_bias_m = x.bh;
  res.height_bias_var_m2 = Sigma(kBh, kBh);
  for (const HeightObs& o : heights) res.n_heights += o.use;
  std::set<SensorId> used_anchors;
  double sq = 0.0;
  for (const Obs& o : obs) {
    if (!o.use) continue;
    ++res.n_ranges;
    used_anchors.insert(o.r.anchor);
    const double r = residual(o, x);
    sq += r * r;
  }
  res.n_anchors = static_cast<int>(used_anchors.size());
  res.rms_m = res.n_ranges ? std::sqrt(sq / res.n_ranges) : 0.0;
  res.sigma_yaw_deg = std::sqrt(so3::yawVariance(res.imu.q_ItoG, res.cov.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta))) / kDeg;
  res.sigma_p_m = std::sqrt(res.cov.block<3, 3>(ImuErr::kP, ImuErr::kP).diagonal().maxCoeff());
  if (!res.cov.allFinite() || res.sigma_yaw_deg > options_.max_sigma_yaw_deg || res.sigma_p_m > options_.max_sigma_p_m) {
    reason_ = "motion alignment: pose not determined yet (σ_yaw " + std::to_string(res.sigma_yaw_deg) + " deg, σ_p " +
              std::to_string(res.sigma_p_m) + " m; needs horizontal acceleration and spread anchors)";
    return std::nullopt;
  }
  if (res.n_ranges < options_.min_ranges || res.n_anchors < options_.min_anchors) {
    reason_ = "motion alignment: too few inlier ranges (" + std::to_string(res.n_ranges) + ")";
    return std::nullopt;
  }
  reason_.clear();
  return res;
}

}  // namespace meshnav::estimator
