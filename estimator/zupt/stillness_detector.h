#pragma once
/// @file stillness_detector.h
/// @brief Evidence of rest from the IMU alone, for zero-velocity updates and static
/// initialization when no FLIGHT_STATE is received.
///
/// Over a sliding window of `window_s` the sample standard deviations of the specific force and
/// of the angular rate (per axis, the largest) must stay below
///   σ_f,max = max(k · σ_a √rate, acc_floor),   σ_ω,max = max(k · σ_ω √rate, gyro_floor)
/// (σ_a, σ_ω the noise densities, rate the sample rate, k = `noise_factor`), the mean specific
/// force must be within `gravity_tolerance` of |g| and the mean rate below `max_mean_rate`
/// (a smooth turn has a small spread but is not rest). A real hovering or walking body shakes far more.

#include <deque>

#include "common/types.h"

namespace meshnav::estimator {

struct StillnessOptions {
  double window_s = 0.5;               ///< [s]
  double noise_factor = 4.0;           ///< k [-]
  double acc_floor_m_s2 = 0.03;        ///< [m/s²]
  double gyro_floor_rad_s = 0.005;     ///< [rad/s]
  double gravity_tolerance_m_s2 = 0.3; ///< [m/s²]
  double max_mean_rate_rad_s = 0.02;   ///< above any gyro bias worth flying with [rad/s]
};

class StillnessDetector {
 public:
  StillnessDetector(const StillnessOptions& options, double acc_noise_density, double gyro_noise_density,
                    double gravity_m_s2);
  /// Adds a sample; returns whether the body is at rest over the window ending at it.
  bool add(const ImuSample& s);
  bool still() const { return still_; }

 private:
  StillnessOptions options_;
  double acc_nd_, gyro_nd_, gravity_;
  std::deque<ImuSample> window_;
  bool still_ = false;
};

}  // namespace meshnav::estimator
