#pragma once
/// @file zupt_measurement.h
/// @brief Zero-velocity pseudo-measurement while landed, tied to the latest IMU reading.

#include <Eigen/Core>

#include "common/time.h"

namespace meshnav::estimator {

struct ZuptMeasurement {
  Timestamp t;
  Eigen::Vector3d acc_m_s2 = Eigen::Vector3d::Zero();   ///< latest specific force reading a_m [m/s²]
  Eigen::Vector3d gyro_rad_s = Eigen::Vector3d::Zero(); ///< latest angular rate reading ω_m [rad/s]
  double sigma_acc_m_s2 = 0.2;
  double sigma_gyro_rad_s = 0.01;
  double sigma_vel_m_s = 0.02;
};

}  // namespace meshnav::estimator
