#pragma once
/// @file perturbed_run.h
/// @brief A filter run made from a dataset's truth with slow errors (a drifting offset and tilt), as
/// a filter's poses look, with a covariance that covers them: the smoother's input in its unit tests
/// and benchmark (header-only).

#include <algorithm>
#include <cmath>

#include "common/dataset.h"
#include "estimator/core/so3.h"
#include "smoother/run_smoother.h"

namespace meshnav::smoother::testing {

/// Every other truth pose, offset by up to `offset_m` and turned by `angle_deg` (σ at least 1 cm
/// and 0.5°).
inline FilterRun perturbedRun(const Dataset& ds, double offset_m, double angle_deg) {
  FilterRun run;
  for (size_t i = 0; i < ds.ground_truth.size(); i += 2) {
    const auto& g = ds.ground_truth[i];
    const double t = g.t.sec();
    PoseEstimate e;
    e.t = g.t;
    e.p_IinG = g.p_IinG + offset_m * Eigen::Vector3d(std::sin(0.3 * t), std::cos(0.2 * t), 0.5 * std::sin(0.1 * t));
    const Eigen::Vector3d tilt =
        angle_deg * M_PI / 180.0 * Eigen::Vector3d(std::cos(0.25 * t), 0.5, std::sin(0.15 * t)).normalized();
    e.q_ItoG = Eigen::Quaterniond(g.q_ItoG.toRotationMatrix() * estimator::so3::expMap(tilt));
    e.cov_p_m2 = Eigen::Matrix3d::Identity() * std::pow(std::max(offset_m, 0.01), 2);
    e.cov_theta_rad2 = Eigen::Matrix3d::Identity() * std::pow(std::max(angle_deg, 0.5) * M_PI / 180.0, 2);
    run.poses.push_back(e);
  }
  return run;
}

}  // namespace meshnav::smoother::testing
