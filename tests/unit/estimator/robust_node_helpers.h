#pragma once
/// @file robust_node_helpers.h
/// @brief Running an EstimatorNode over a simulated dataset against its ground truth, and the
/// scenarios of the robustness sweep (scripts/robustness.py) as simulator options.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>

#include "estimator/node/estimator_node.h"
#include "sim/scenario_simulator.h"

namespace meshnav::estimator::test {

/// Runs `ds` through a node; `hook(node, t)` after every input. Returns the position error at
/// the end and records the largest error after `t_check`.
struct RunResult {
  double final_error_m = 0.0;
  double max_error_after_m = 0.0;
  double max_angle_error_after_deg = 0.0;  ///< largest rotation angle of R̂ᵀR after t_check [deg]
  double rms_error_after_m = 0.0;          ///< position RMSE over the IMU samples after t_check [m]
  Health final_health = Health::Initializing;
};

template <typename Hook>
RunResult run(EstimatorNode& node, const Dataset& ds, double t_check, Hook hook) {
  RunResult res;
  size_t gi = 0;
  double sq = 0.0;
  long n = 0;
  for (const auto& in : mergeInTimeOrder(ds)) {
    node.onInput(in);
    hook(node, inputTime(in));
    if (!std::holds_alternative<ImuSample>(in) || !node.initialized()) continue;
    const Timestamp t = inputTime(in);
    while (gi + 1 < ds.ground_truth.size() && ds.ground_truth[gi + 1].t <= t) ++gi;
    const double e = (node.pose()->p_IinG - ds.ground_truth[gi].p_IinG).norm();
    res.final_error_m = e;
    if (t.sec() <= t_check) continue;
    res.max_error_after_m = std::max(res.max_error_after_m, e);
    sq += e * e;
    ++n;
    const double angle = node.pose()->q_ItoG.angularDistance(ds.ground_truth[gi].q_ItoG) * 180.0 / M_PI;
    res.max_angle_error_after_deg = std::max(res.max_angle_error_after_deg, angle);
  }
  res.final_health = node.health();
  if (n > 0) res.rms_error_after_m = std::sqrt(sq / static_cast<double>(n));
  return res;
}

/// One scenario as the sweep draws it (the fields of its YAML; docs/scenarios.md).
struct SweepScenario {
  uint64_t seed = 1;
  sim::TrajectoryKind trajectory = sim::TrajectoryKind::Spiral;
  Eigen::Vector3d hall_m = Eigen::Vector3d(10, 8, 5);
  sim::AnchorLayoutKind layout = sim::AnchorLayoutKind::Paper;
  int tags = 2, known = 4, unknown = 0;
  double sigma_range_m = 0.15, outliers = 0.0, drop = 0.0;
  std::string imu_grade = "fc";
  double duration_s = 90.0;
  /// Scale of the IMU's rotor vibration (meshnav_sim --vibration): 0 for the incidents of sweeps
  /// drawn before the simulator had it (an airborne IMU that read like rest).
  double vibration = 1.0;
};

inline sim::SimulationOptions simulationOptions(const SweepScenario& c) {
  sim::SimulationOptions so;
  so.seed = c.seed;
  so.trajectory_kind = c.trajectory;
  so.hall_size_m = c.hall_m;
  so.anchor_layout = c.layout;
  so.n_tags = c.tags;
  so.n_known_anchors = c.known;
  so.n_unknown_anchors = c.unknown;
  so.uwb.sigma_range_m = c.sigma_range_m;
  so.uwb.outlier_fraction = c.outliers;
  so.uwb.drop_fraction = c.drop;
  so.imu = sim::ImuNoiseOptions::forGrade(c.imu_grade);
  so.imu.vibration_acc_m_s2 *= c.vibration;
  so.imu.vibration_gyro_rad_s *= c.vibration;
  so.duration_s = c.duration_s;
  return so;
}

}  // namespace meshnav::estimator::test
