#pragma once
/// @file trajectory_metrics.h
/// @brief Pose accuracy and consistency of an estimated trajectory against ground truth.
///
/// Association: every estimate at time t_k is compared with the ground truth interpolated at t_k
/// (linear in position, slerp in orientation; common/pose_interpolation.h). Estimates outside the
/// ground-truth span or in a ground-truth gap are skipped and counted.
///
/// Metrics over the N selected samples k = 1..N (e_k the per-sample error norm, position [m] or
/// orientation angle [deg]):
///  - RMSE  = √( (1/N) Σ e_k² )      — root of the mean squared error norm;
///  - ARMSE = (1/N) Σ e_k            — the "average RMSE" of the paper's toolbox (cnspy
///    `ARMSE_p`, `ARMSE_q`): the arithmetic mean of the per-sample error norms (each sample's
///    RMSE over its own 3 axes, times √3). ARMSE ≤ RMSE, equal only for a constant error norm;
///  - ANEES = (1/M) Σ ε_k over the M ≤ N samples with a positive-definite covariance, and its
///    95 % acceptance interval for χ²(3M)/M (chi_square.h).

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/diagnostics.h"
#include "common/types.h"
#include "eval/chi_square.h"
#include "eval/pose_error.h"
#include "eval/trajectory_alignment.h"

namespace meshnav::eval {

/// Which samples enter the metrics.
struct EvalOptions {
  double skip_first_s = 0.0;     ///< ignore estimates in the first S seconds after the first estimate [s]
  bool only_flying = false;      ///< ignore estimates while landed (needs flight_state.csv)
  double max_gt_gap_s = 0.2;     ///< ground-truth samples further apart cannot be interpolated [s]
  double confidence = 0.95;      ///< of the ANEES acceptance interval
  /// Alignment of the estimate to the truth (--align); nullopt: se3 when truth.yaml says
  /// align_required, else none.
  std::optional<AlignmentMode> align;
  bool baseline = true;            ///< also evaluate the multilateration baseline
  /// Leave out the stretches where groundtruth.csv contradicts imu.csv's gyro (truth_consistency.h).
  bool check_truth_with_gyro = true;
  double baseline_window_s = 0.03;  ///< its epoch length [s]: one RTLS message of ISAS-Walk1 (51 ms apart)
  /// Windows [t0, t1] of dataset time [s] (the files' stamps) whose ground truth is left out, so
  /// their estimates enter neither the alignment nor the figures (--exclude; a sensor outage the
  /// figures should not mix with the rest of the run).
  std::vector<std::pair<double, double>> exclude_windows_s;
};

/// Associates estimates with interpolated ground truth. `flight_states` may be empty (then every
/// sample counts as flying). Skipped samples are counted in `diag` ("eval:outside_ground_truth").
/// Every associated sample is returned (the `skip_first_s` / `only_flying` selection is applied by
/// `computeTrajectoryMetrics`, so that plots can show the whole run).
std::vector<PoseError> associate(const std::vector<PoseEstimate>& estimates,
                                 const std::vector<PoseSample>& ground_truth,
                                 const std::vector<FlightStateSample>& flight_states,
                                 const EvalOptions& options, Diagnostics& diag);

/// Summary statistics of one error component (position or orientation).
struct ErrorStats {
  int n = 0;                 ///< samples in the accuracy figures
  double rmse = 0.0;         ///< √(mean e²)
  double armse = 0.0;        ///< mean e
  double max = 0.0;          ///< max e
  Eigen::Vector3d rmse_axes = Eigen::Vector3d::Zero();  ///< per axis √(mean e_i²)
  int n_nees = 0;            ///< samples with a positive-definite covariance
  double anees = 0.0;        ///< mean NEES (NaN when n_nees = 0)
  ChiSquareBounds anees_bounds;  ///< acceptance interval of the ANEES for n_nees samples, 3 dof
  double frac_nees_in_single_bounds = 0.0;  ///< share of samples with NEES within the 1-sample interval
};

struct TrajectoryMetrics {
  int n_associated = 0;      ///< estimates with ground truth
  int n_selected = 0;        ///< of those, entering the metrics (skip / flying selection)
  double t_first_s = 0.0;    ///< first selected sample [s]
  double t_last_s = 0.0;     ///< last selected sample [s]
  ErrorStats position;       ///< units m
  ErrorStats orientation;    ///< units deg (NEES dimensionless)
};

/// True when sample `e` enters the metrics (`t0` = time of the first associated sample).
bool isSelected(const PoseError& e, Timestamp t0, const EvalOptions& options);

TrajectoryMetrics computeTrajectoryMetrics(const std::vector<PoseError>& errors,
                                           const EvalOptions& options);

/// Landed state at t (last flight-state sample at or before t; false before the first one).
bool landedAt(const std::vector<FlightStateSample>& sorted_states, Timestamp t);

}  // namespace meshnav::eval
