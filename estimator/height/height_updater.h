#pragma once
/// @file height_updater.h
/// @brief The height sensor's update on the filter (HeightOptions): a downward rangefinder over
/// the floor, or the carried-height pseudo-sensor of a hand-held rig (setup `carried_height`),
/// through HeightModel, χ² gated at `height.gate_probability`, with the sensor's bias b_H as an
/// instance added at the first usable reading (its prior: the in-motion alignment's estimate when
/// it used heights, else N(0, height.init_bias_sigma_m²): the floor is z = 0 of G).
///
/// A reading is not used when it is below `height.min_range_m` (rangefinders clamp at the bottom
/// of their range), while the body is tilted beyond `height.max_tilt_deg` (the beam may miss the
/// floor; not for a carried height), or when `height_id` is an estimated anchor's id.

#include <optional>
#include <string>
#include <utility>

#include "common/types.h"
#include "estimator/core/estimator_options.h"
#include "estimator/filter/fusion_strategy.h"
#include "estimator/height/height_model.h"

namespace meshnav::estimator {

class HeightUpdater {
 public:
  /// `options`: the height options (the carried height's figures already in them for a carried
  /// rig); `p_IH`: the sensor's lever arm (zero for a carried height).
  HeightUpdater(const HeightOptions& options, SensorId height_id, const Eigen::Vector3d& p_IH, bool carried);
  bool enabled() const { return options_.enabled; }
  bool carried() const { return carried_; }
  /// Why `s` is not used now (a counter name: "height_below_min_range", "height_tilted",
  /// "height_id_is_an_anchor"), or "" when it is.
  std::string refusal(const FusionStrategy& f, const HeightSample& s) const;
  /// Adds the bias instance to `f` when it has none yet (logged when `log`).
  void ensureBiasState(FusionStrategy& f, Timestamp t, bool log) const;
  /// Fuses `s` into `f` (already propagated to s.t, the bias instance present).
  UpdateResult update(FusionStrategy& f, const HeightSample& s) const;
  /// The bias (mean, variance [m, m²]) the in-motion alignment estimated: the prior of the bias
  /// instance; none: N(0, height.init_bias_sigma_m²).
  void setBiasPrior(const std::optional<std::pair<double, double>>& b) { bias_prior_ = b; }
  /// The counters' name of this sensor ("height" or "carried_height").
  const char* typeName() const { return carried_ ? "carried_height" : "height"; }

 private:
  HeightOptions options_;
  SensorId height_id_;
  bool carried_;
  HeightModel model_;
  double gate_ = 0.0;  ///< χ²₁ quantile of `height.gate_probability` (0: no gate)
  std::optional<std::pair<double, double>> bias_prior_;
};

}  // namespace meshnav::estimator
