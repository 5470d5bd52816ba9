#pragma once
/// @file process_noise_adapter.h
/// @brief Scales the IMU's white-noise densities to what the range innovations show
/// (covariance matching; docs/robustness.md, "Process noise from the innovations").
///
/// A datasheet density describes the sensor at rest. In use, scale-factor, misalignment,
/// vibration and sampling errors add to it, by an amount no setup file states (ISAS-Walk1: a
/// hand-held rig needs about 30× the ICM-20948's densities). Too small a Q makes the filter trust
/// dead reckoning over ranges: innovations grow beyond their predicted variance, the χ² gate then
/// rejects the ranges that should correct it, and the estimate runs away.
///
/// The adapter watches the normalized innovation squared NIS = ν²/S of tag–anchor ranges
/// (χ²(1) if consistent), accepted or gated (a filter that has drifted shows itself by gating).
/// Every `batch` ranges it forms the ratio r = median NIS / 0.455 (the median of χ²(1)) and,
/// outside the dead band [`lower_ratio`, `upper_ratio`], multiplies the variance scale λ by r,
/// clamped to [1/`max_shrink`, `max_grow`] per batch, with λ ∈ [1, `max_scale`]. The filter adds
/// (λ − 1)·Q_white(Δt) to each propagation step, so the densities become √λ·σ. Growth is fast
/// and shrinking slow: a λ too small diverges, one too large only costs some smoothing. Defaults
/// chosen on the 200-run sweep, ISAS-Walk1 and a 10× understated IMU (docs/robustness.md): upper
/// bound 2.2, λ ≤ 100 (densities at most 10×). λ shrinks again at rest, where a MEMS IMU is as
/// good as its datasheet.
///
/// **λ also grows where the IMU densities are right** (docs/robustness.md, "Process noise from
/// the innovations"). Gated outliers count in the median (15 % of them lift a consistent batch's
/// median to r ≈ 1.5), the median of 40 values spreads by about ±0.4, so single batches cross 2.2;
/// and where H P Hᵀ ≪ R (the usual case in flight) a growth hardly lowers the NIS, so nothing
/// undoes it: on the 200-run sweep (seed 4, exact densities) λ ends at a median of 16. Taking the
/// median over the accepted ranges and growing only after two batches in a row kept λ at 1 there
/// but cost ISAS-Walk1 12 %; those two options were off by default and are gone (issue 33). The
/// ratchet is a limit of this rule, not a model of the IMU's error (issue 34).
/// Growth only helps while the predicted range variance H P Hᵀ is small against the range noise R:
/// once the state is already less certain than one range (median H P Hᵀ / R above
/// `max_prior_ratio`), a NIS that stays high comes from the range model (biases, NLOS, too few
/// anchors), not from Q, and growing λ further would only turn the filter into a per-range
/// position fix that follows every range error (a spiral under four coplanar ceiling anchors ran
/// λ to 10⁴ and diverged). λ then holds.
/// λ is state of the estimate: it is snapshotted and rewound with the filter.

#include <vector>

namespace meshnav::estimator {

struct ProcessNoiseAdaptOptions {
  bool enabled = true;
  int batch = 40;             ///< tag-anchor ranges per decision [-]
  double upper_ratio = 2.2;   ///< median NIS ratio above which λ grows [-]
  double lower_ratio = 0.5;   ///< median NIS ratio below which λ shrinks [-]
  double max_grow = 10.0;     ///< largest growth of λ per decision (factor) [-]
  double max_shrink = 1.2;    ///< largest shrink of λ per decision (factor) [-]
  double max_scale = 100.0;   ///< largest λ (densities up to 10×) [-]
  double max_prior_ratio = 1.0;  ///< no growth while median H P Hᵀ / R of the batch exceeds this [-]
};

class ProcessNoiseAdapter {
 public:
  ProcessNoiseAdapter() = default;
  explicit ProcessNoiseAdapter(const ProcessNoiseAdaptOptions& options) : options_(options) {}

  /// NIS of one tag–anchor range and its predicted variance ratio H P Hᵀ / R (the state's share of
  /// the innovation variance against the range noise's); gated ranges count too (`accepted` is
  /// not used: a drifted filter shows itself by gating).
  /// Returns true when λ changed.
  bool onRangeNis(double nis, double prior_ratio = 0.0, bool accepted = true);
  /// Variance scale λ ≥ 1 of the IMU white noise.
  double scale() const { return scale_; }
  /// Median NIS ratio of the last decision (1 if consistent); 0 before the first.
  double lastRatio() const { return last_ratio_; }
  /// Decisions (batches of `batch` ranges) taken so far, whether λ changed or not.
  long decisions() const { return decisions_; }

 private:
  ProcessNoiseAdaptOptions options_;
  double scale_ = 1.0;
  double last_ratio_ = 0.0;
  long decisions_ = 0;
  std::vector<double> batch_;
  std::vector<double> prior_ratios_;
};

}  // namespace meshnav::estimator
