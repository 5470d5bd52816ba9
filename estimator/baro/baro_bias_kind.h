#pragma once
/// @file baro_bias_kind.h
/// @brief Instance kind of a barometer (estimator/core/kind_traits.h): its height bias b_P [m]
/// (h_baro = p_z + (R p_IP)_z + b_P), one error state b_P = b̂_P + δb_P, random walk
/// `baro.bias_rw_m_per_sqrt_s`; kept across a restart.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "estimator/core/estimator_options.h"
#include "estimator/core/kind_traits.h"

namespace meshnav::estimator {

struct BaroBiasKind : ScalarStateKind<BaroBiasKind> {
  static constexpr const char* kName = "baro";
  static double randomWalk(const EstimatorOptions& o) { return o.baro.bias_rw_m_per_sqrt_s; }
  /// The bias may have absorbed the runaway a recovery follows: its variance is widened to at
  /// least the initial σ² (`baro.init_bias_sigma_m`).
  static Eigen::MatrixXd keptCovariance(const Eigen::MatrixXd& cov, const EstimatorOptions& o) {
    return Eigen::MatrixXd::Constant(1, 1, std::max(cov(0, 0), std::pow(o.baro.init_bias_sigma_m, 2)));
  }
  /// A restart keeps the bias with the baro reference pressure it is relative to (the node uses it
  /// only when the restarted estimator has the same reference).
  static Restart restart(const EstimatorOptions& o) { return o.baro.enabled ? Restart::kKept : Restart::kPrior; }
};

}  // namespace meshnav::estimator
