#pragma once
/// @file baseline_evaluation.h
/// @brief Alignment of a trajectory to ground truth in another frame, and the multilateration
/// baseline evaluated the same way as the estimate (docs/real_data.md: real recordings always show plain
/// multilateration beside the estimate).

#include <optional>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "common/types.h"
#include "eval/multilateration.h"
#include "eval/trajectory_alignment.h"
#include "eval/trajectory_metrics.h"

namespace meshnav::eval {

/// Fits `mode` on the positions of `estimates` against the ground truth interpolated at their
/// times (within `max_gt_gap_s`) and transforms every estimate into the truth's frame. Returns the
/// transform, or nullopt (estimates unchanged) when it cannot be fitted. None: identity.
std::optional<RigidTransform> alignToGroundTruth(std::vector<PoseEstimate>& estimates,
                                                 const std::vector<PoseSample>& ground_truth, AlignmentMode mode,
                                                 double max_gt_gap_s);

/// The multilateration baseline of one dataset.
struct BaselineEvaluation {
  Multilateration::Stats stats;
  double window_s = 0.0;                    ///< epoch length used [s]
  std::optional<RigidTransform> transform;  ///< its own alignment to the truth (same mode)
  std::vector<PoseEstimate> fixes;          ///< after alignment
  TrajectoryMetrics trajectory;             ///< position errors only (orientation is not estimated)
  std::vector<std::string> notes;
};

/// Multilaterates `ranges` with the known anchors and tags of `setup`, aligns the fixes with
/// `mode` and computes their errors against `ground_truth` with `options` (selection included).
BaselineEvaluation evaluateBaseline(const std::vector<RangeSample>& ranges, const SystemSetup& setup,
                                    const std::vector<PoseSample>& ground_truth,
                                    const std::vector<FlightStateSample>& flight_states, AlignmentMode mode,
                                    const EvalOptions& options, Diagnostics& diag);

}  // namespace meshnav::eval
