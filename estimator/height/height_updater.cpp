/// @file height_updater.cpp
/// @brief HeightUpdater: a rangefinder or carried-height reading as an update (height_updater.h).

#include "estimator/height/height_updater.h"

#include <spdlog/spdlog.h>

#include <cmath>

#include "common/chi_square.h"

namespace meshnav::estimator {

HeightUpdater::HeightUpdater(const HeightOptions& options, SensorId height_id, const Eigen::Vector3d& p_IH,
                             bool carried)
    : options_(options),
      height_id_(height_id),
      carried_(carried),
      model_(p_IH, options.tilt_correction, options.max_tilt_deg * M_PI / 180.0) {
  if (options_.gate_probability > 0) gate_ = chi2Quantile(1, options_.gate_probability);
}

std::string HeightUpdater::refusal(const FusionStrategy& f, const HeightSample& s) const {
  if (s.range_m < options_.min_range_m) return "height_below_min_range";  // clamped at the bottom of its range
  if (!carried_ && !model_.valid(f.state())) return "height_tilted";
  if (f.state().values<AnchorKind>().count(height_id_)) return "height_id_is_an_anchor";
  return "";
}

void HeightUpdater::ensureBiasState(FusionStrategy& f, Timestamp t, bool log) const {
  if (f.state().values<HeightBiasKind>().count(height_id_)) return;
  // The floor is at z = 0 of G: the bias is near zero unless the sensor sits far from the IMU.
  const double b = bias_prior_ ? bias_prior_->first : 0.0;
  const double var = bias_prior_ ? bias_prior_->second : std::pow(options_.init_bias_sigma_m, 2);
  f.addInstance<HeightBiasKind>(height_id_, b, Eigen::MatrixXd::Constant(1, 1, var));
  if (log)
    spdlog::info("estimator: {} {} added at t={} with bias {:.3f} m (σ {:.3f} m)",
                 carried_ ? "carried height" : "height sensor", height_id_, formatSeconds(t), b, std::sqrt(var));
}

UpdateResult HeightUpdater::update(FusionStrategy& f, const HeightSample& s) const {
  const HeightMeasurement z{s.t, height_id_, s.range_m, options_.sigma_m};
  return f.update(model_.linearize(z, f.state()), gate_);
}

}  // namespace meshnav::estimator
