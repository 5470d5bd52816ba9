#pragma once
/// @file range_updater.h
/// @brief A UWB range's update on the filter (UwbOptions, RangeModel): which ranges are fused,
/// their linearization with the robust weighting, and the χ² gate.
///
/// A range z between devices a and b (raw `range_m`, or `range_corr_m` with
/// `uwb.use_corrected_range`) is fused through RangeModel (z = β‖p_a − p_b‖ + γ_ab + n, each
/// position a tag's p_IinG + R p_TinI, an exactly known anchor, or an estimated anchor state),
/// with the Huber weighting (`uwb.huber_k`: beyond k σ the residual's variance grows so that its
/// influence stays bounded, at most `uwb.huber_max_prior_ratio` times the prior's) and gated at the
/// χ²₁ quantile of `uwb.gate_probability`. Not fused, by rule of the configuration:
///  - ranges between two estimated anchors with DAH when `uwb.dah_fuse_estimated_anchor_pairs` is
///    off ("range_dah_anchor_pair_skipped");
///  - ranges between two calibrated anchors unless `uwb.fuse_calibrated_anchor_pairs`
///    ("range_calibrated_anchor_pair_skipped");
///  - ranges RangeModel cannot classify (unknown device: "unknown_id"; its other status names).

#include <optional>
#include <string>

#include "common/types.h"
#include "estimator/core/estimator_options.h"
#include "estimator/filter/fusion_strategy.h"
#include "estimator/uwb/range_measurement.h"
#include "estimator/uwb/uwb_network.h"

namespace meshnav::estimator {

class RangeUpdater {
 public:
  /// `dah`: the strategy is DAH (estimated-anchor pairs may be left out).
  RangeUpdater(const UwbOptions& options, bool dah);
  bool enabled() const { return options_.enabled; }
  /// The measurement of sample `s` (raw or corrected range, its variance).
  RangeMeasurement measurement(const RangeSample& s) const;
  /// Why `z` is not fused (a counter name), or "" when it is; checked before propagation.
  std::string refusal(const RangeMeasurement& z, const FusionStrategy& f, const UwbNetwork& network) const;
  /// The linearization at the filter's current state with the robust weighting; nullopt with
  /// `*why` (a RangeModel status name) when the model cannot be evaluated.
  std::optional<Linearization> linearize(const RangeMeasurement& z, const FusionStrategy& f,
                                         const UwbNetwork& network, std::string* why) const;
  /// The gated update.
  UpdateResult update(FusionStrategy& f, const Linearization& lin) const { return f.update(lin, gate_); }
  /// H P Hᵀ / R of a scalar update from its NIS = ν²/S, S = H P Hᵀ + R (0 when not defined).
  static double priorRatio(const Linearization& lin, const UpdateResult& r);

 private:
  UwbOptions options_;
  double gate_ = 0.0;  ///< χ²₁ quantile of `uwb.gate_probability` (0: no gate)
  bool skip_estimated_anchor_pairs_ = false;
};

}  // namespace meshnav::estimator
