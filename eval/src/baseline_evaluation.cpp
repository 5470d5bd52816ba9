#include "eval/baseline_evaluation.h"

#include "common/pose_interpolation.h"

namespace meshnav::eval {

std::optional<RigidTransform> alignToGroundTruth(std::vector<PoseEstimate>& estimates,
                                                 const std::vector<PoseSample>& ground_truth, AlignmentMode mode,
                                                 double max_gt_gap_s) {
  if (mode == AlignmentMode::None) return RigidTransform{};
  std::vector<Eigen::Vector3d> p_est, p_true;
  const Duration max_gap = Duration::fromSec(max_gt_gap_s);
  for (const auto& e : estimates) {
    if (const auto g = interpolatePose(ground_truth, e.t, max_gap)) {
      p_est.push_back(e.p_IinG);
      p_true.push_back(g->p_IinG);
    }
  }
  const auto T = alignPositions(p_est, p_true, mode);
  if (T) {
    for (auto& e : estimates) e = T->apply(e);
  }
  return T;
}

BaselineEvaluation evaluateBaseline(const std::vector<RangeSample>& ranges, const SystemSetup& setup,
                                    const std::vector<PoseSample>& ground_truth,
                                    const std::vector<FlightStateSample>& flight_states, AlignmentMode mode,
                                    const EvalOptions& options, Diagnostics& diag) {
  BaselineEvaluation b;
  Multilateration::Options mo;
  mo.window_s = options.baseline_window_s;
  b.window_s = mo.window_s;
  Multilateration ml(mo);
  b.fixes = ml.solve(ranges, setup, diag);
  b.stats = ml.stats();
  if (b.fixes.empty()) {
    b.notes.push_back("multilateration: no fix (" + std::to_string(b.stats.epochs) + " epochs of " +
                      std::to_string(mo.window_s) + " s, " + std::to_string(b.stats.too_few_anchors) +
                      " with fewer than " + std::to_string(mo.min_anchors) + " known anchors)");
    return b;
  }
  b.transform = alignToGroundTruth(b.fixes, ground_truth, mode, options.max_gt_gap_s);
  if (!b.transform) b.notes.push_back("multilateration: alignment " + toString(mode) + " could not be fitted");
  Diagnostics own;  // the estimate's association counters stay the estimate's
  const auto errors = associate(b.fixes, ground_truth, flight_states, options, own);
  b.trajectory = computeTrajectoryMetrics(errors, options);
  return b;
}

}  // namespace meshnav::eval
