#pragma once
/// @file run_smoother.h
/// @brief Smooths a whole recording after a filter run: builds the SmoothingProblem from the
/// dataset (IMU, ranges, setup) and the run folder (the filter's poses as initial values and
/// chunk priors, its anchors, its UWB clock delay), solves it chunk by chunk and returns poses at
/// the filter's output times (estimate_smoothed.csv). docs/smoother.md.
///
/// Chunks bound the memory: chunk c covers [s_c, s_c + chunk_s] and gives the poses of
/// [s_c, s_c + chunk_s − overlap_s); the next starts at s_c + chunk_s − overlap_s with the filter's
/// pose and covariance there as its prior, which holds the data before s_c+1 only, so nothing is
/// counted twice. A pose `overlap_s` before a chunk's end has seen that much of the future.

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/dataset.h"
#include "common/diagnostics.h"
#include "common/types.h"
#include "smoother/batch_smoother.h"

namespace meshnav::smoother {

/// What the smoother takes from a filter run folder.
struct FilterRun {
  std::vector<PoseEstimate> poses;                ///< estimate.csv
  std::map<SensorId, Eigen::Vector3d> anchors;    ///< anchors.csv, the newest row of each id
  std::vector<AnchorInit> calibrations;           ///< calibration.yaml (calibrated anchors' γ, β)
  double uwb_clock_offset_s = 0.0;                ///< status.txt uwb_clock_offset_s (δ_u) [s]
  bool has_clock_offset = false;
};

/// Reads estimate.csv (required), anchors.csv, calibration.yaml and status.txt (optional) of `dir`.
FilterRun readFilterRun(const std::string& dir, Diagnostics& diag);

struct RunSmootherOptions {
  double knot_period_s = 0.1;   ///< spacing of the knots [s]
  double chunk_s = 300.0;       ///< data solved at once [s] (about 70 MB at 222 ranges/s)
  double overlap_s = 10.0;      ///< future data each chunk's last output pose has seen [s]
  bool use_corrected_range = false;  ///< range_corr instead of range_raw (as uwb.use_corrected_range)
  /// The estimator options file the run was made with (meshnav run --config): its IMU noise, range,
  /// ZUPT and height models are the smoother's; empty: the estimator's defaults
  std::string estimator_config;
  /// Ranges to the anchors the run estimated (anchors.csv, calibrated or uncertain ones) are used
  /// with their final position; false: only the setup's known anchors (a smoothed path for
  /// calibrating those anchors must not already hold them)
  bool use_run_anchors = true;
  /// The anchors the run estimated (and the setup's uncertain ones) are unknowns of the fit, a
  /// bundle adjustment of trajectory and anchors (AnchorUnknown); false: taken as the run left them.
  /// On by default: paper sequences 1–12, anchors 0.060 → 0.054 m, pose ANEES 7.5 → 5.4 (docs/smoother.md)
  bool estimate_anchors = true;
  /// A filter pose that turns by more than this against the gyro within one output step is a
  /// re-initialization (a gravity flip, a recovery); the knots before it take their initial
  /// attitude from the gyro, back from the pose after it [rad]
  double reinit_jump_rad = 0.2;
  /// White-noise density of the angular rate interpolated across an IMU gap [rad/s/√s]: a body's
  /// rate departs from the straight line between the samples around a gap by a few 0.1 rad/s over
  /// a second of hand or flight motion. The accelerometer's is the estimator's imu.gap_sigma_acc_m_s2.
  double gap_sigma_gyro_rad_s = 0.1;
  /// The range errors' line-of-sight / NLOS mixture (BatchSmootherOptions::nlos_*) is the
  /// estimator's, so that smoother and filter share one model: ε, b₀ and μ from uwb.nlos_fraction,
  /// uwb.nlos_min_excess_m and uwb.nlos_mean_excess_m of `estimator_config` (or the estimator's
  /// defaults), whatever `solver` holds. Set: this ε instead (tests, comparisons) [-]
  std::optional<double> nlos_fraction;
  BatchSmootherOptions solver;
};

/// Per-chunk figures.
struct ChunkReport {
  double t0_s = 0.0, t1_s = 0.0;
  SmootherResult result;           ///< knots left out (only the statistics)
  double gravity_z_sign = -1.0;    ///< gravity along −z (−1) or +z (+1) of G, by the data
  int reinit_jumps = 0;            ///< filter re-initializations inside the chunk
  int imu_gaps = 0;                ///< IMU gaps (> imu.max_dt_s) inside the chunk, bridged by the gap model
};

struct SmoothedRun {
  std::vector<PoseEstimate> poses;  ///< at the filter's times within the smoothed span
  std::vector<AnchorEstimate> anchors;  ///< with `estimate_anchors`: the last chunk's estimate of each
  std::vector<ChunkReport> chunks;
  int n_ranges_used = 0, n_ranges_skipped = 0;  ///< skipped: anchor unknown, tag–tag, anchor–anchor
};

/// Smooths the run. `progress(line)` gets one line per chunk pass.
SmoothedRun smoothRun(const Dataset& ds, const FilterRun& run, const RunSmootherOptions& options,
                      const std::function<void(const std::string&)>& progress = nullptr);

}  // namespace meshnav::smoother
