#pragma once
/// @file run_evaluation.h
/// @brief Evaluation of one run (estimate.csv, anchors.csv) against its dataset's ground truth
/// (groundtruth.csv, truth.yaml, flight_state.csv, setup.yaml).

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "eval/anchor_metrics.h"
#include "eval/baseline_evaluation.h"
#include "eval/trajectory_metrics.h"

namespace meshnav::eval {

/// The smoother's estimate of the same run (estimate_smoothed.csv, meshnav smooth), scored as the
/// filter's is (its own alignment fit when the mode aligns).
struct SmoothedEvaluation {
  std::vector<PoseEstimate> estimates;
  std::optional<RigidTransform> alignment_transform;
  std::vector<PoseError> errors;
  TrajectoryMetrics trajectory;
};

struct RunEvaluation {
  std::string dataset_dir;
  std::string run_dir;
  EvalOptions options;
  bool has_ground_truth = false;   ///< groundtruth.csv read with at least 2 poses
  bool has_truth_yaml = false;     ///< truth.yaml read
  bool has_flight_state = false;
  std::vector<std::string> notes;  ///< human-readable reasons for missing parts
  std::vector<PoseSample> ground_truth;
  std::vector<PoseEstimate> estimates;
  AlignmentMode alignment = AlignmentMode::None;  ///< applied to the estimate (and the baseline)
  std::string alignment_reason;                   ///< why this mode ("--align", truth.yaml, ...)
  std::optional<RigidTransform> alignment_transform;  ///< estimate frame → truth frame, when fitted
  std::optional<BaselineEvaluation> baseline;     ///< multilateration on the same ranges.csv
  std::vector<PoseError> errors;   ///< every associated estimate (selection flags via isSelected)
  TrajectoryMetrics trajectory;
  std::optional<AnchorMetrics> anchors;  ///< nullopt without anchors.csv or truth.yaml
  std::optional<SmoothedEvaluation> smoothed;  ///< when the run folder holds estimate_smoothed.csv
  std::map<std::string, int64_t> diagnostics;  ///< counters of bad input (Diagnostics::snapshot)
};

/// Reads and evaluates. Never throws for missing or bad files: what cannot be evaluated is left
/// empty and explained in `notes` (and logged). `calibration_yaml` (optional) replaces the initial
/// anchor beliefs; when empty, `<run>/calibration.yaml` is used if it exists.
RunEvaluation evaluateRun(const std::string& dataset_dir, const std::string& run_dir,
                          const EvalOptions& options, const std::string& calibration_yaml = "");

/// Rows skipped for a time stamp that is not a number or does not fit ("<file>:bad_time"). The
/// figures leave them out; meshnav_eval then fails (exit status 3) instead of reporting them as
/// healthy.
int64_t skippedTimeRows(const RunEvaluation& ev);

}  // namespace meshnav::eval
