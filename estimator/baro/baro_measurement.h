#pragma once
/// @file baro_measurement.h
/// @brief Barometric height measurement: pressure converted to height above the reference level.

#include "common/time.h"
#include "common/types.h"

namespace meshnav::estimator {

struct BaroMeasurement {
  Timestamp t;
  SensorId baro_id = 2;
  double height_m = 0.0;  ///< h = heightFromPressure(p, p_ref) [m]
  double sigma_m = 0.25;  ///< |dh/dp| σ_p [m]
};

}  // namespace meshnav::estimator
