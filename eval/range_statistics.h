#pragma once
/// @file range_statistics.h
/// @brief Per ordered pair (UWB_ID1 → UWB_ID2) range error statistics, as the paper's range
/// evaluation toolbox computes them: constant bias and noise standard deviation.
///
/// Error of one range: e = z − d, measured minus true distance [m]. With the range model
/// z = β·d + γ + ν (paper eq. z_kl, estimator/README.md), E[e] = γ + (β − 1)·d, i.e. γ for β = 1.
///
/// Three estimators of (bias, σ) from the errors of one pair:
///  - `Gate`:      drop gross outliers |e| > max_error, then mean and (population) std.
///  - `Histogram`: the toolbox's filtered histogram. After the gate, bin the errors into B equal
///    bins over [min e, max e]; take the k = ⌊B·f/2⌋ most populated bins (f = assumed inlier
///    fraction, ties → the later bin); let c be the mean of their left edges, e₋/e₊ the smallest
///    and largest of those edges; keep errors with c − 2(c − e₋) < e < c + 2(e₊ − c) and return
///    their mean and population std. This trims the heavy tails of real SDS-TWR errors (NLOS,
///    multipath) that the plain gate keeps. Defaults B = 50, f = 0.3, max_error = 1 m as in the toolbox.
///    Caveat (measured): on purely Gaussian errors the window is only about ±0.9σ wide, so this σ is
///    about half the true σ (the mean is fine). It reproduces the toolbox's tables, not σ_d.
///  - `Clip`:      after the gate, start from the median and 1.4826·MAD and iterate
///    "keep |e − μ| < 3σ, μ = mean, σ = std / 0.98658" (0.98658 = std of a unit Gaussian truncated
///    at ±3σ) to a fixed point: unbiased for Gaussian noise with a minority of outliers, so it
///    recovers a simulated γ and σ_d.

#include <map>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "common/types.h"
#include "eval/true_range_model.h"

namespace meshnav::eval {

enum class BiasMethod { Gate, Histogram, Clip };

struct RangeStatsOptions {
  BiasMethod method = BiasMethod::Histogram;
  double max_error_m = 1.0;       ///< gross outlier gate |e| ≤ max_error [m]
  int histogram_bins = 50;        ///< B
  double inlier_fraction = 0.3;   ///< f
};

/// Bias and noise of one set of errors.
struct BiasEstimate {
  double bias_m = 0.0;   ///< mean of the kept errors [m]
  double std_m = 0.0;    ///< population std of the kept errors [m]
  int n_in = 0;          ///< errors given
  int n_used = 0;        ///< errors kept
  double lower_m = 0.0;  ///< acceptance window actually used [m]
  double upper_m = 0.0;
};

/// Robust bias/σ of `errors` (NaN fields when nothing is left).
BiasEstimate estimateBias(const std::vector<double>& errors, const RangeStatsOptions& options);

struct PairRangeStats {
  SensorId id1 = 0, id2 = 0;     ///< initiator → responder
  int n_ranges = 0;              ///< measured ranges of the pair
  int n_with_truth = 0;          ///< of those with a true distance
  double mean_true_m = 0.0;      ///< mean true distance of the associated ranges [m]
  double median_error_m = 0.0;   ///< median of all associated errors [m]
  BiasEstimate estimate;
  std::vector<double> t_s;       ///< times of the associated ranges [s] (for plots)
  std::vector<double> errors_m;  ///< all associated errors e = z − d [m] (for plots)
};

/// Statistics for every ordered pair present in `ranges`. Ranges without a true distance are
/// counted in `diag` ("range_stats:no_truth_<reason>").
std::map<std::pair<SensorId, SensorId>, PairRangeStats> computeRangeStatistics(
    const std::vector<RangeSample>& ranges, const TrueRangeModel& truth,
    const RangeStatsOptions& options, Diagnostics& diag);

}  // namespace meshnav::eval
