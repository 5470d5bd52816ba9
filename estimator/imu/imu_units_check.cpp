/// @file imu_units_check.cpp
/// @brief ImuUnitsCheck: the IMU's units from gravity and from plausible rates (imu_units_check.h).

#include "estimator/imu/imu_units_check.h"

#include <algorithm>
#include <cmath>
#include <spdlog/fmt/fmt.h>

namespace meshnav::estimator {

std::string ImuUnitsCheck::add(const ImuSample& s) {
  if (!fault_.empty()) return "";
  if (!window_start_) window_start_ = s.t;
  if (!accel_checked_) sum_f_ += s.acc_m_s2.norm();
  rates_.push_back(s.gyro_rad_s.norm());
  if ((s.t - *window_start_).sec() < options_.window_s) return "";
  // A full window: the accelerometer's verdict on the first one, the gyro's on every one.
  if (!accel_checked_) {
    accel_checked_ = true;
    const double mean_f = sum_f_ / static_cast<double>(rates_.size());
    if (std::abs(mean_f - options_.gravity_m_s2) > options_.gravity_tolerance_m_s2) {
      const bool in_g = std::abs(mean_f - 1.0) < 0.3;
      fault_ = fmt::format("the accelerometer reads a mean |f| of {:.2f} over its first {:.0f} s where gravity gives "
                           "{:.2f} m/s^2: {}",
                           mean_f, options_.window_s, options_.gravity_m_s2,
                           in_g ? "in g, not m/s^2? (multiply by 9.81)" : "not in m/s^2, or scaled");
      return fault_;
    }
  }
  std::nth_element(rates_.begin(), rates_.begin() + static_cast<long>(rates_.size() / 2), rates_.end());
  const double median = rates_[rates_.size() / 2];
  if (median > options_.max_median_rate_rad_s) {
    fault_ = fmt::format("the gyro reads a median |w| of {:.1f} over {:.0f} s, {:.0f} deg/s if that is rad/s: in "
                         "deg/s, not rad/s? (multiply by pi/180)",
                         median, options_.window_s, median * 180.0 / M_PI);
    return fault_;
  }
  rates_.clear();  // the next window (the gyro's check runs once per window_s)
  window_start_.reset();
  return "";
}

}  // namespace meshnav::estimator
