#pragma once
/// @file range_dataset.h
/// @brief Loads what a range evaluation needs from a folder: measured ranges and a true-range model.
///
/// Two layouts are recognised:
///  - a meshnav dataset (docs/formats.md): ranges.csv, truth.yaml (all anchors, true pair biases),
///    groundtruth.csv and setup.yaml (tag lever arms) for the tag ranges;
///  - a toolbox recording (shared/data/real-t1-a3-loiter): *ranges*.csv measured by each device,
///    true_ranges*.csv (true tag-to-anchor distances), config.yaml (`abs_anchor_positions`).

#include <map>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "common/types.h"
#include "eval/true_range_model.h"

namespace meshnav::eval {

struct RangeEvaluationInput {
  std::string kind;                  ///< "meshnav dataset" or "recording"
  std::vector<RangeSample> ranges;   ///< measured, sorted by time
  TrueRangeModel truth;
  std::vector<PairBias> truth_pairs; ///< simulated γ, β, σ (meshnav dataset only)
  std::vector<std::string> notes;    ///< what could not be used
};

/// Throws std::runtime_error naming the folder/file when nothing can be evaluated.
RangeEvaluationInput loadRangeEvaluationInput(const std::string& dir, Diagnostics& diag, double max_dt_s = 0.05);

/// `abs_anchor_positions: {id: [x, y, z]}` of a config/setup YAML. The toolbox writes flow maps as
/// `{1:[x, y, z]}` (no space after the colon), which YAML parsers reject, so a space is inserted.
std::map<SensorId, Eigen::Vector3d> readAbsAnchorPositions(const std::string& path);

}  // namespace meshnav::eval
