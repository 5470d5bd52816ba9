#pragma once
/// @file recovery_policy.h
/// @brief When the estimator compares its pose with a fresh alignment and replaces it
/// (RecoveryOptions, docs/robustness.md "Health", "Recovery").
///
/// The model: the aligner's pose from the last window of ranges and IMU increments (position and
/// yaw with covariance P_a) and the filter's (P_f) are two estimates of the same pose; their
/// difference d = (Δp, Δψ) is N(0, S) with S = P_f + P_a (independent data when the filter is
/// wrong), so χ² = dᵀS⁻¹d has 4 degrees of freedom. The filter is replaced when
///  - health is `lost` (the gate refuses the ranges: the filter cannot recover by itself), or
///  - χ² exceeds `recovery.degraded_disagreement_chi2` (23.5: 99.99 % of χ²₄) while health is
///    `degraded` and the accepted ranges do not fit (degraded by gating alone, with the accepted
///    ranges fitting, is what NLOS outliers look like: the filter is then more likely right), or
///    within `init.motion_window_s` after an IMU gap of `recovery.after_gap_check_min_s` (the gap's
///    dead reckoning may be metres off before the gate notices).
/// Alignments are tried at most every `recovery.retry_s`; health itself is evaluated at most
/// every `kEvaluationPeriod_s`.

#include <optional>

#include "common/time.h"
#include "estimator/core/estimator_options.h"
#include "estimator/core/imu_state.h"
#include "estimator/health/health_monitor.h"
#include "estimator/init/motion_aligner.h"

namespace meshnav::estimator {

class RecoveryPolicy {
 public:
  /// Health's windows are seconds long (HealthOptions); evaluating it more often than this changes
  /// no decision and costs a covariance eigen-decomposition per input [s].
  static constexpr double kEvaluationPeriod_s = 0.1;

  /// `after_gap_window_s`: init.motion_window_s.
  RecoveryPolicy(const RecoveryOptions& options, double after_gap_window_s)
      : options_(options), after_gap_window_s_(after_gap_window_s) {}

  /// Health is due for evaluation at `t` (taken as evaluated).
  bool evaluationDue(Timestamp t);
  /// An IMU gap of `gap_s` ended at IMU time `t`: after a long one the aligned pose is compared
  /// for a window.
  void noteImuGap(Timestamp t, double gap_s);
  /// Within the comparison window after a gap.
  bool afterGap(Timestamp t) const { return check_after_gap_until_ && t <= *check_after_gap_until_; }
  /// An alignment is due at `t` for health `h` (`accepted_fit`: the accepted ranges fit); taken
  /// as tried.
  bool alignmentDue(Timestamp t, Health h, bool accepted_fit);
  /// χ² (4 dof) between the filter's position and yaw (`x`, IMU covariance `P`) and an aligned
  /// pose, both covariances.
  static double disagreement(const ImuState& x, const ImuMatrix& P, const AlignmentResult& r);
  /// The aligned pose contradicts the filter (χ² beyond the bound).
  bool contradicts(double chi2) const { return chi2 > options_.degraded_disagreement_chi2; }
  double bound() const { return options_.degraded_disagreement_chi2; }
  /// Forgets the retry time and the after-gap window (a reset of the node).
  void reset() {
    last_try_.reset();
    check_after_gap_until_.reset();
  }
  /// Also the evaluation time (the clock jumped back).
  void resetAll() {
    reset();
    last_evaluation_.reset();
  }
  /// The replay node of a re-run: the live node's after-gap window.
  void copyGapWindowFrom(const RecoveryPolicy& live) { check_after_gap_until_ = live.check_after_gap_until_; }

 private:
  RecoveryOptions options_;
  double after_gap_window_s_;
  std::optional<Timestamp> last_try_, last_evaluation_, check_after_gap_until_;
};

}  // namespace meshnav::estimator
