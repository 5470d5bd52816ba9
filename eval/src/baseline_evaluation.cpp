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
  std::vector<SensorId> tags;
  b.fixes = ml.solve(ranges, setup, diag, &tags);
  b.stats = ml.stats();
  if (b.fixes.empty()) {
    b.notes.push_back("multilateration: no fix (" + std::to_string(b.stats.epochs) + " epochs of " +
                      std::to_string(mo.window_s) + " s, " + std::to_string(b.stats.too_few_anchors) +
                      " with fewer than " + std::to_string(mo.min_anchors) + " known anchors)");
    return b;
  }
  // Each fix is its tag's position: aligned to the truth's tag positions (the truth's pose with the
  // lever arm), then moved to the body by the truth's attitude, so that the lever arm costs the
  // baseline nothing. Fixes without truth at their time cannot be compared and are dropped.
  const Duration max_gap = Duration::fromSec(options.max_gt_gap_s);
  std::vector<PoseEstimate> kept;
  std::vector<Eigen::Vector3d> p_fix, p_tag_true;
  std::vector<Eigen::Matrix3d> R_true;
  std::vector<Eigen::Vector3d> lever;
  for (size_t i = 0; i < b.fixes.size(); ++i) {
    const auto g = interpolatePose(ground_truth, b.fixes[i].t, max_gap);
    if (!g) continue;
    const Eigen::Vector3d p_TinI = setup.rel_tag_positions.at(tags[i]);
    kept.push_back(b.fixes[i]);
    p_fix.push_back(b.fixes[i].p_IinG);
    R_true.push_back(g->q_ItoG.toRotationMatrix());
    lever.push_back(p_TinI);
    p_tag_true.push_back(g->p_IinG + R_true.back() * p_TinI);
  }
  b.fixes = std::move(kept);
  b.transform = mode == AlignmentMode::None ? std::optional<RigidTransform>(RigidTransform{})
                                            : alignPositions(p_fix, p_tag_true, mode);
  if (!b.transform) {
    b.notes.push_back("multilateration: alignment " + toString(mode) + " could not be fitted");
  } else {
    for (size_t i = 0; i < b.fixes.size(); ++i) {
      b.fixes[i] = b.transform->apply(b.fixes[i]);
      b.fixes[i].p_IinG -= R_true[i] * lever[i];
    }
  }
  Diagnostics own;  // the estimate's association counters stay the estimate's
  const auto errors = associate(b.fixes, ground_truth, flight_states, options, own);
  b.trajectory = computeTrajectoryMetrics(errors, options);
  return b;
}

}  // namespace meshnav::eval
