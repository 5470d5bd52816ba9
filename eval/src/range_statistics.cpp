#include "eval/range_statistics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace meshnav::eval {

namespace {

void meanStd(const std::vector<double>& v, double& mean, double& std) {
  if (v.empty()) {
    mean = std = std::numeric_limits<double>::quiet_NaN();
    return;
  }
  mean = std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  double ss = 0.0;
  for (double x : v) ss += (x - mean) * (x - mean);
  std = std::sqrt(ss / static_cast<double>(v.size()));
}

double median(std::vector<double> v) {
  const size_t n = v.size();
  std::nth_element(v.begin(), v.begin() + n / 2, v.end());
  double m = v[n / 2];
  if (n % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + n / 2));
  return m;
}

/// Sigma clipping from median/MAD (see header). Returns the kept errors and the window.
std::vector<double> sigmaClip(const std::vector<double>& e, double& lo, double& hi) {
  constexpr double kMadToSigma = 1.4826;
  constexpr double kClip = 3.0;
  constexpr double kTruncatedStd = 0.98658;  // std of N(0,1) restricted to |x| < 3
  double mu = median(e);
  std::vector<double> dev;
  dev.reserve(e.size());
  for (double x : e) dev.push_back(std::abs(x - mu));
  double sigma = kMadToSigma * median(dev);
  if (!(sigma > 0.0)) return e;
  std::vector<double> kept;
  for (int it = 0; it < 50; ++it) {
    kept.clear();
    for (double x : e)
      if (std::abs(x - mu) < kClip * sigma) kept.push_back(x);
    if (kept.size() < 2) return e;
    double m, s;
    meanStd(kept, m, s);
    s /= kTruncatedStd;
    const bool converged = std::abs(m - mu) < 1e-9 && std::abs(s - sigma) < 1e-9;
    mu = m;
    sigma = s;
    if (converged || !(sigma > 0.0)) break;
  }
  lo = mu - kClip * sigma;
  hi = mu + kClip * sigma;
  return kept;
}

}  // namespace

BiasEstimate estimateBias(const std::vector<double>& errors, const RangeStatsOptions& o) {
  BiasEstimate b;
  b.n_in = static_cast<int>(errors.size());
  std::vector<double> gated;
  gated.reserve(errors.size());
  for (double e : errors)
    if (std::isfinite(e) && std::abs(e) <= o.max_error_m) gated.push_back(e);
  b.lower_m = -o.max_error_m;
  b.upper_m = o.max_error_m;

  std::vector<double> kept = gated;
  const int bins = std::max(1, o.histogram_bins);
  const int k = std::max(1, static_cast<int>(std::floor(bins * o.inlier_fraction * 0.5)));
  if (o.method == BiasMethod::Histogram && gated.size() >= 2) {
    const auto [mn_it, mx_it] = std::minmax_element(gated.begin(), gated.end());
    const double lo = *mn_it, hi = *mx_it;
    if (hi > lo) {
      const double width = (hi - lo) / bins;
      std::vector<int> counts(bins, 0);
      for (double e : gated) {
        int i = static_cast<int>(std::floor((e - lo) / width));
        counts[std::clamp(i, 0, bins - 1)]++;  // the last bin includes its right edge
      }
      std::vector<int> order(bins);
      std::iota(order.begin(), order.end(), 0);
      // Ascending by count, ties by index: the k last are the most populated (later bin on ties).
      std::stable_sort(order.begin(), order.end(), [&](int a, int c) { return counts[a] < counts[c]; });
      double sum = 0.0, emin = std::numeric_limits<double>::infinity(), emax = -emin;
      for (int j = bins - k; j < bins; ++j) {
        const double left = lo + order[j] * width;
        sum += left;
        emin = std::min(emin, left);
        emax = std::max(emax, left);
      }
      const double c = sum / k;
      const double wlo = c - 2.0 * (c - emin);
      const double whi = c + 2.0 * (emax - c);
      std::vector<double> inside;
      for (double e : gated)
        if (e > wlo && e < whi) inside.push_back(e);
      if (inside.size() >= 2) {
        kept = std::move(inside);
        b.lower_m = wlo;
        b.upper_m = whi;
      }
    }
  }
  if (o.method == BiasMethod::Clip && gated.size() >= 3) {
    double lo = b.lower_m, hi = b.upper_m;
    kept = sigmaClip(gated, lo, hi);
    b.lower_m = lo;
    b.upper_m = hi;
    b.n_used = static_cast<int>(kept.size());
    meanStd(kept, b.bias_m, b.std_m);
    if (kept.size() >= 2 && kept.size() < gated.size()) b.std_m /= 0.98658;  // truncation correction
    return b;
  }
  b.n_used = static_cast<int>(kept.size());
  meanStd(kept, b.bias_m, b.std_m);
  return b;
}

std::map<std::pair<SensorId, SensorId>, PairRangeStats> computeRangeStatistics(
    const std::vector<RangeSample>& ranges, const TrueRangeModel& truth,
    const RangeStatsOptions& options, Diagnostics& diag) {
  std::map<std::pair<SensorId, SensorId>, PairRangeStats> out;
  std::map<std::pair<SensorId, SensorId>, double> sum_true;
  for (const auto& r : ranges) {
    const auto key = std::make_pair(r.id_initiator, r.id_responder);
    auto& s = out[key];
    s.id1 = r.id_initiator;
    s.id2 = r.id_responder;
    ++s.n_ranges;
    TrueRangeMiss miss = TrueRangeMiss::None;
    const auto d = truth.trueRange(r, &miss);
    if (!d) {
      switch (miss) {
        case TrueRangeMiss::UnknownDevice: diag.count("range_stats:no_truth_unknown_device"); break;
        case TrueRangeMiss::NoTrajectory: diag.count("range_stats:no_truth_no_trajectory"); break;
        default: diag.count("range_stats:no_truth_time_gap"); break;
      }
      continue;
    }
    ++s.n_with_truth;
    sum_true[key] += *d;
    s.t_s.push_back(r.t.sec());
    s.errors_m.push_back(r.range_m - *d);
  }
  for (auto& [key, s] : out) {
    s.mean_true_m = s.n_with_truth > 0 ? sum_true[key] / s.n_with_truth
                                       : std::numeric_limits<double>::quiet_NaN();
    if (!s.errors_m.empty()) {
      std::vector<double> tmp = s.errors_m;
      std::nth_element(tmp.begin(), tmp.begin() + tmp.size() / 2, tmp.end());
      s.median_error_m = tmp[tmp.size() / 2];
    } else {
      s.median_error_m = std::numeric_limits<double>::quiet_NaN();
    }
    s.estimate = estimateBias(s.errors_m, options);
  }
  return out;
}

}  // namespace meshnav::eval
