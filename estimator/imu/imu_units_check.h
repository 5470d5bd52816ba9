#pragma once
/// @file imu_units_check.h
/// @brief Whether an IMU stream is in the units the estimator assumes, specific force in m/s² and
/// angular rate in rad/s (issue 36: an accelerometer in g gave an accelerometer bias of −8.85 m/s²
/// against a prior σ of 0.05, a gyro in deg/s an RMSE of 52 m, both with exit 0).
///
/// The physics it relies on:
///  - over the first `window_s` of a recording the mean |f| is gravity's within
///    `gravity_tolerance_m_s2` (a body at rest, hovering, walking or even accelerating at 2 m/s²
///    for the whole window reads 9.8–10.0 m/s²; an accelerometer in g reads about 1);
///  - no platform of this domain turns at a median `max_median_rate_rad_s` (500 deg/s) over
///    `window_s`: the real recordings reach a median of 0.87 rad/s at most over 2 s, the same in
///    deg/s at least 12 "rad/s" on a slow flight.
/// Both verdicts are physical limits with a tenfold margin, not tuned on a recording.

#include <optional>
#include <string>
#include <vector>

#include "common/time.h"
#include "common/types.h"

namespace meshnav::estimator {

class ImuUnitsCheck {
 public:
  struct Options {
    double window_s = 2.0;                 ///< [s]
    double gravity_m_s2 = 9.81;            ///< |g| [m/s²]
    double gravity_tolerance_m_s2 = 3.0;   ///< [m/s²]
    double max_median_rate_rad_s = 8.7;    ///< 500 deg/s [rad/s]
  };
  explicit ImuUnitsCheck(const Options& options) : options_(options) {}

  /// Feeds one sample (time order); returns the fault the first time one is found, else "".
  std::string add(const ImuSample& s);
  /// The fault found ("" while none): the stream is not in m/s² and rad/s.
  const std::string& fault() const { return fault_; }
  /// A new stream (a Reset command): nothing checked, no fault.
  void reset() { *this = ImuUnitsCheck(options_); }

 private:
  Options options_;
  std::optional<Timestamp> window_start_;
  double sum_f_ = 0.0;         ///< Σ |f| over the first window (the accelerometer's) [m/s²]
  std::vector<double> rates_;  ///< |ω| of the current window [rad/s]
  bool accel_checked_ = false;
  std::string fault_;
};

}  // namespace meshnav::estimator
