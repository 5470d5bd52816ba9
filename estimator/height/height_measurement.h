#pragma once
/// @file height_measurement.h
/// @brief Downward laser rangefinder measurement: distance along the beam to the floor.

#include "common/time.h"
#include "common/types.h"

namespace meshnav::estimator {

struct HeightMeasurement {
  Timestamp t;
  SensorId height_id = 3;  ///< the rangefinder's instance (its bias state)
  double range_m = 0.0;    ///< measured distance along the beam [m]
  double sigma_m = 0.05;   ///< range noise σ [m]
};

}  // namespace meshnav::estimator
