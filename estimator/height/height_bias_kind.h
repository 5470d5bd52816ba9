#pragma once
/// @file height_bias_kind.h
/// @brief Instance kind of a downward rangefinder (estimator/core/kind_traits.h): its bias b_H [m]
/// (height_model.h), one error state b_H = b̂_H + δb_H, random walk
/// `height.bias_rw_m_per_sqrt_s`; a recovery and a restart keep it.

#include <Eigen/Core>

#include "estimator/core/estimator_options.h"
#include "estimator/core/kind_traits.h"

namespace meshnav::estimator {

struct HeightBiasKind : ScalarStateKind<HeightBiasKind> {
  static constexpr const char* kName = "height";
  static double randomWalk(const EstimatorOptions& o) { return o.height.bias_rw_m_per_sqrt_s; }
  static Eigen::MatrixXd keptCovariance(const Eigen::MatrixXd& cov, const EstimatorOptions&) { return cov; }
  /// A restart keeps the converged bias (before issue 11 it restarted from its prior).
  static Restart restart(const EstimatorOptions& o) { return o.height.enabled ? Restart::kKept : Restart::kPrior; }
};

}  // namespace meshnav::estimator
