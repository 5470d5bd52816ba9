#pragma once
/// @file range_measurement.h
/// @brief A two-way range between UWB devices a and b as fused by the filter.

#include <Eigen/Core>

#include "common/time.h"
#include "common/types.h"

namespace meshnav::estimator {

struct RangeMeasurement {
  Timestamp t;
  SensorId a = 0;       ///< initiator
  SensorId b = 0;       ///< responder
  double z_m = 0.0;     ///< measured range [m]
  double R_m2 = 0.0;    ///< variance from the source [m²], 0 = unknown
  /// The body's angular rate at t as the gyro measured it (newest reading, bias not removed), ω_IinI
  /// [rad/s]: where a tag on a lever arm was a clock offset earlier (range_model.h). Zero: unknown.
  Eigen::Vector3d omega_IinI_rad_s = Eigen::Vector3d::Zero();
};

}  // namespace meshnav::estimator
