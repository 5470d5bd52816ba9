/// @file rest_measurement.cpp
/// @brief restMeasurement and restGate (rest_measurement.h).
#include "estimator/zupt/rest_measurement.h"

#include <algorithm>
#include <cmath>

#include "common/chi_square.h"

namespace meshnav::estimator {

ZuptMeasurement restMeasurement(const ImuSample& s, const RestRateMean& rest, const ZuptOptions& o,
                                double gyro_noise_density, double noise_scale, bool flight_state) {
  ZuptMeasurement z;
  z.t = s.t;
  z.acc_m_s2 = s.acc_m_s2;
  z.sigma_acc_m_s2 = o.sigma_acc_m_s2;
  const double rest_sigma = flight_state ? o.sigma_gyro_rad_s : o.stillness_sigma_gyro_rad_s;
  if (rest.span() > 0.0) {
    const double mean_sigma = rest.sigma(gyro_noise_density * std::sqrt(noise_scale));
    z.gyro_rad_s = rest.mean();
    z.sigma_gyro_rad_s = std::hypot(rest_sigma, mean_sigma);
  } else {
    z.gyro_rad_s = s.gyro_rad_s;
    z.sigma_gyro_rad_s = std::max(rest_sigma, o.stillness_sigma_gyro_rad_s);
  }
  z.sigma_vel_m_s = flight_state ? o.sigma_vel_m_s : o.stillness_sigma_vel_m_s;
  return z;
}

double restGate(int dim, const ZuptOptions& o, bool flight_state) {
  return flight_state ? 0.0 : chi2Quantile(dim, o.stillness_gate_probability);
}

}  // namespace meshnav::estimator
