#pragma once
/// @file airspeed_scale_kind.h
/// @brief Instance kind of a pitot airspeed sensor (estimator/core/kind_traits.h): its scale factor
/// s (v_measured = s · |v_air|), one error state s = ŝ + δs, constant. A scratch kind that checked
/// the recipe "A new sensor kind" of docs/contributing.md (no measurement model, no input).

#include <Eigen/Core>

#include "estimator/core/estimator_options.h"
#include "estimator/core/kind_traits.h"

namespace meshnav::estimator {

struct AirspeedScaleKind : ScalarStateKind<AirspeedScaleKind> {
  static constexpr const char* kName = "airspeed";
  static double randomWalk(const EstimatorOptions&) { return 0.0; }
  static Eigen::MatrixXd keptCovariance(const Eigen::MatrixXd& cov, const EstimatorOptions&) { return cov; }
};

}  // namespace meshnav::estimator
