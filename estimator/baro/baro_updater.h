#pragma once
/// @file baro_updater.h
/// @brief The barometer's update on the filter (BaroOptions): the height h = H(p, p_ref) from the
/// pressure against the reference pressure p_ref (common/atmosphere.h), with σ_h = |∂H/∂p| σ_p
/// (`baro.pressure_sigma_pa`), through BaroModel (h = (p_IinG + R p_IP)_z + b_P), χ² gated at
/// `baro.gate_probability`. Without a reference pressure (none in the setup, no landed data or
/// alignment gave one) there is no height to fuse.

#include <optional>

#include "common/types.h"
#include "estimator/baro/baro_model.h"
#include "estimator/core/estimator_options.h"
#include "estimator/filter/fusion_strategy.h"

namespace meshnav::estimator {

class BaroUpdater {
 public:
  BaroUpdater(const BaroOptions& options, SensorId baro_id, const Eigen::Vector3d& p_IP);
  bool enabled() const { return options_.enabled; }
  /// The reference pressure heights are measured against [Pa] (none: no update possible).
  const std::optional<double>& reference() const { return reference_pa_; }
  void setReference(const std::optional<double>& pa) { reference_pa_ = pa; }
  /// Fuses the height of pressure reading `s` into `f` (already propagated to s.t); needs a reference.
  UpdateResult update(FusionStrategy& f, const BaroSample& s) const;

 private:
  BaroOptions options_;
  SensorId baro_id_;
  BaroModel model_;
  double gate_ = 0.0;  ///< χ²₁ quantile of `baro.gate_probability` (0: no gate)
  std::optional<double> reference_pa_;
};

}  // namespace meshnav::estimator
