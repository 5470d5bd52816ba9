#pragma once
/// @file anchor_metrics.h
/// @brief Anchor position errors (paper Tab. II/III): per anchor, the initial estimate p★ (the
/// belief the calibration handed to the filter: first row of the anchor in anchors.csv, or the
/// calibration YAML when given) and the final estimate p̂ (last row), against truth.yaml.
///
/// Errors: ‖p_true − p★‖, ‖p_true − p̂‖ [m]; NEES of the initial belief
/// ε★ = (p_true − p★)ᵀ Σ★⁻¹ (p_true − p★) ~ χ²(3) for a consistent calibration (paper §V-B quotes
/// ε★ = 159.6 against the 99.7 % threshold 13.93 = χ²⁻¹₃(0.997)).

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "common/types.h"

namespace meshnav::eval {

struct AnchorError {
  SensorId id = 0;
  bool known = false;          ///< exactly known: in setup.yaml without a σ (else calibrated or refined online)
  bool has_truth = false;
  Eigen::Vector3d p_true = Eigen::Vector3d::Zero();
  int n_estimates = 0;         ///< rows in anchors.csv
  AnchorEstimate initial;      ///< p★ and Σ★
  AnchorEstimate final_est;    ///< p̂ and Σ̂ (last row)
  double initial_error_m = 0.0;
  double final_error_m = 0.0;
  std::optional<double> initial_nees;  ///< nullopt: Σ★ not positive definite or no truth
  std::optional<double> final_nees;
};

struct AnchorMetrics {
  std::vector<AnchorError> anchors;   ///< sorted by id
  /// Means over the estimated anchors (not known: calibrated, or given with a σ and refined online)
  /// that have truth; NaN when there is none.
  double mean_initial_error_m = 0.0;
  double mean_final_error_m = 0.0;
  int n_estimated = 0;
};

/// `known_positions`: the exactly known anchors (setup.yaml entries without a σ).
/// `initial_override`: id → initial belief (e.g. from the calibration YAML), replacing the first
/// anchors.csv row. Anchors without truth are listed with has_truth = false (and reported once to
/// `diag` as "eval:anchor_without_truth").
AnchorMetrics computeAnchorMetrics(const std::vector<AnchorEstimate>& anchor_rows,
                                   const std::map<SensorId, Eigen::Vector3d>& truth_positions,
                                   const std::map<SensorId, Eigen::Vector3d>& known_positions,
                                   const std::map<SensorId, AnchorEstimate>& initial_override,
                                   Diagnostics& diag);

/// Reads a calibration result YAML (docs/formats.md: a sequence of entries, or a map with key `anchors`
/// holding one, each with `id`, `p_AinG`, `p_AinG_cov` (9 values row-major), optional `t`).
/// Throws std::runtime_error naming the file and the key on a malformed file.
std::map<SensorId, AnchorEstimate> readCalibrationYaml(const std::string& path);

}  // namespace meshnav::eval
