#pragma once
/// @file multilateration.h
/// @brief Plain per-epoch multilateration of tag–anchor ranges: the baseline that meshnav_eval
/// shows beside the estimate (docs/real_data.md), with no IMU, no filter and no bias model.
///
/// Epochs: for each tag of the vehicle (setup.yaml `rel_tag_positions`), its ranges to known
/// anchors (`abs_anchor_positions`, either end of the range) are taken in time order; an epoch
/// starts at the first unused range and holds every range of that tag up to `window_s` later (one
/// RTLS message in the ISAS bag, where all ranges share one stamp). An anchor seen twice keeps its
/// latest range. Epochs with fewer than `min_anchors` distinct anchors are skipped and counted.
///
/// Solution: the tag position x minimising Σ_i ρ(‖x − a_i‖ − z_i) (a_i anchor [m], z_i range [m],
/// ρ the Huber loss with threshold k), by iteratively re-weighted Gauss–Newton:
///   r_i = ‖x − a_i‖ − z_i,  J_i = (x − a_i)ᵀ / ‖x − a_i‖,  w_i = min(1, k / |r_i|),
///   (Jᵀ W J) δx = −Jᵀ W r,  x ← x + δx,  until ‖δx‖ < 1e-9 m or `max_iterations`.
/// Start: the tag's previous fix when it is at most `reuse_fix_s` old, else the linear solution of
/// ‖x‖² − 2 a_iᵀ x + ‖a_i‖² = z_i² with the mean equation subtracted (least squares, SVD).
/// A fix is rejected (counted) when Jᵀ W J is near-singular (anchor geometry) or the RMS of the
/// residuals after convergence exceeds `max_rms_residual_m`.
///
/// A fix is the tag's position. `solve` can also return which tag each fix belongs to, so that the
/// evaluation compares it with the truth's tag position (the truth's pose and the lever arm,
/// evaluateBaseline); the estimator's orientation is never used for it (that would mix the baseline
/// with the estimate under test).

#include <map>
#include <vector>

#include "common/diagnostics.h"
#include "common/setup.h"
#include "common/types.h"

namespace meshnav::eval {

class Multilateration {
 public:
  struct Options {
    double window_s = 0.03;           ///< length of an epoch [s]
    int min_anchors = 4;              ///< distinct anchors needed for a fix
    double huber_k_m = 0.15;          ///< Huber threshold [m]
    int max_iterations = 30;
    double max_rms_residual_m = 0.5;  ///< fixes with a larger RMS residual are rejected [m]
    double reuse_fix_s = 1.0;         ///< start from the previous fix if it is this recent [s]
  };

  /// Counts of one run.
  struct Stats {
    int epochs = 0;             ///< epochs formed (any number of anchors)
    int too_few_anchors = 0;    ///< epochs skipped: fewer than min_anchors distinct anchors
    int degenerate = 0;         ///< rejected: anchor geometry leaves the position undetermined
    int large_residual = 0;     ///< rejected: RMS residual above max_rms_residual_m
    int fixes = 0;              ///< positions returned
    int ranges_used = 0;        ///< tag–known-anchor ranges considered
  };

  explicit Multilateration(Options options) : options_(options) {}

  /// Fixes of every tag in time order, as pose estimates (position only: identity orientation,
  /// zero covariance, so that NEES is not computed for them). Counters also go to `diag`
  /// ("multilateration:*").
  /// `fix_tags`: when given, the tag of each fix (same order).
  std::vector<PoseEstimate> solve(const std::vector<RangeSample>& ranges, const SystemSetup& setup,
                                  Diagnostics& diag, std::vector<SensorId>* fix_tags = nullptr);

  /// One epoch: anchor positions a_i [m] and ranges z_i [m] (same length, ≥ 3), start `x0`.
  /// Returns the position, or nullopt (and sets `reason`) when degenerate or the residual is large.
  std::optional<Eigen::Vector3d> solveEpoch(const std::vector<Eigen::Vector3d>& anchors_m,
                                            const std::vector<double>& ranges_m, const Eigen::Vector3d& x0,
                                            const char** reason = nullptr) const;

  /// Linear start: least-squares solution of the differenced squared-range equations; nullopt
  /// when the anchors are coplanar or fewer than 4.
  static std::optional<Eigen::Vector3d> linearSolution(const std::vector<Eigen::Vector3d>& anchors_m,
                                                       const std::vector<double>& ranges_m);

  const Stats& stats() const { return stats_; }

 private:
  Options options_;
  Stats stats_;
};

}  // namespace meshnav::eval
