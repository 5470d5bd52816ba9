/// @file baro_updater.cpp
/// @brief BaroUpdater: a pressure reading as a height update (baro_updater.h).

#include "estimator/baro/baro_updater.h"

#include <cmath>

#include "common/atmosphere.h"
#include "common/chi_square.h"

namespace meshnav::estimator {

BaroUpdater::BaroUpdater(const BaroOptions& options, SensorId baro_id, const Eigen::Vector3d& p_IP)
    : options_(options), baro_id_(baro_id), model_(p_IP) {
  if (options_.gate_probability > 0) gate_ = chi2Quantile(1, options_.gate_probability);
}

UpdateResult BaroUpdater::update(FusionStrategy& f, const BaroSample& s) const {
  BaroMeasurement z;
  z.t = s.t;
  z.baro_id = baro_id_;
  z.height_m = atmosphere::heightFromPressure(s.pressure_pa, *reference_pa_);
  z.sigma_m = std::abs(atmosphere::dHeightDPressure(s.pressure_pa, *reference_pa_)) * options_.pressure_sigma_pa;
  return f.update(model_.linearize(z, f.state()), gate_);
}

}  // namespace meshnav::estimator
