#include "eval/trajectory_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/pose_interpolation.h"

namespace meshnav::eval {

bool landedAt(const std::vector<FlightStateSample>& sorted_states, Timestamp t) {
  auto it = std::upper_bound(sorted_states.begin(), sorted_states.end(), t,
                             [](Timestamp tt, const FlightStateSample& s) { return tt < s.t; });
  if (it == sorted_states.begin()) return false;
  return std::prev(it)->landed;
}

std::vector<PoseError> associate(const std::vector<PoseEstimate>& estimates,
                                 const std::vector<PoseSample>& ground_truth,
                                 const std::vector<FlightStateSample>& flight_states,
                                 const EvalOptions& options, Diagnostics& diag) {
  std::vector<PoseError> out;
  out.reserve(estimates.size());
  const Duration max_gap = Duration::fromSec(options.max_gt_gap_s);
  for (const auto& est : estimates) {
    // In an excluded window even where the truth left around it is close enough to interpolate.
    const double t_s = est.t.sec();
    if (std::any_of(options.exclude_windows_s.begin(), options.exclude_windows_s.end(),
                    [&](const auto& w) { return t_s >= w.first && t_s <= w.second; })) {
      diag.count("eval:excluded_estimate");
      continue;
    }
    const auto truth = interpolatePose(ground_truth, est.t, max_gap);
    if (!truth) {
      diag.count("eval:outside_ground_truth");
      continue;
    }
    PoseError e = computePoseError(est, *truth);
    e.flying = flight_states.empty() || !landedAt(flight_states, est.t);
    out.push_back(e);
  }
  return out;
}

bool isSelected(const PoseError& e, Timestamp t0, const EvalOptions& options) {
  if ((e.t - t0).sec() < options.skip_first_s) return false;
  if (options.only_flying && !e.flying) return false;
  return true;
}

namespace {

/// Accumulates one error component.
class StatsAccumulator {
 public:
  void add(const Eigen::Vector3d& err, double scale, const std::optional<double>& nees_value,
           double single_lo, double single_hi) {
    const Eigen::Vector3d e = err * scale;
    const double norm = e.norm();
    ++n_;
    sum_norm_ += norm;
    sum_sq_ += norm * norm;
    sum_sq_axes_ += e.cwiseAbs2();
    max_ = std::max(max_, norm);
    if (nees_value) {
      ++n_nees_;
      sum_nees_ += *nees_value;
      if (*nees_value >= single_lo && *nees_value <= single_hi) ++n_in_bounds_;
    }
  }
  ErrorStats result(double confidence) const {
    ErrorStats s;
    s.n = n_;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (n_ > 0) {
      s.rmse = std::sqrt(sum_sq_ / n_);
      s.armse = sum_norm_ / n_;
      s.max = max_;
      s.rmse_axes = (sum_sq_axes_ / n_).cwiseSqrt();
    } else {
      s.rmse = s.armse = s.max = nan;
      s.rmse_axes.setConstant(nan);
    }
    s.n_nees = n_nees_;
    s.anees = n_nees_ > 0 ? sum_nees_ / n_nees_ : nan;
    s.anees_bounds = aneesBounds(n_nees_, 3, confidence);
    s.frac_nees_in_single_bounds = n_nees_ > 0 ? static_cast<double>(n_in_bounds_) / n_nees_ : nan;
    return s;
  }

 private:
  int n_ = 0, n_nees_ = 0, n_in_bounds_ = 0;
  double sum_norm_ = 0.0, sum_sq_ = 0.0, max_ = 0.0, sum_nees_ = 0.0;
  Eigen::Vector3d sum_sq_axes_ = Eigen::Vector3d::Zero();
};

}  // namespace

TrajectoryMetrics computeTrajectoryMetrics(const std::vector<PoseError>& errors,
                                           const EvalOptions& options) {
  TrajectoryMetrics m;
  m.n_associated = static_cast<int>(errors.size());
  const ChiSquareBounds single = aneesBounds(1, 3, options.confidence);
  StatsAccumulator pos, ori;
  bool first = true;
  const Timestamp t0 = errors.empty() ? Timestamp{} : errors.front().t;
  for (const auto& e : errors) {
    if (!isSelected(e, t0, options)) continue;
    if (first) {
      m.t_first_s = e.t.sec();
      first = false;
    }
    m.t_last_s = e.t.sec();
    ++m.n_selected;
    pos.add(e.p_err_m, 1.0, e.nees_p, single.lower, single.upper);
    ori.add(e.theta_err_rad, 180.0 / M_PI, e.nees_theta, single.lower, single.upper);
  }
  m.position = pos.result(options.confidence);
  m.orientation = ori.result(options.confidence);
  return m;
}

}  // namespace meshnav::eval
