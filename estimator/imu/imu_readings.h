#pragma once
/// @file imu_readings.h
/// @brief The IMU readings a propagation step over [t₀, t₁] holds constant (ImuPropagator).
///
/// The propagator holds one reading over its step, so the reading must be the signal at the
/// step's middle t_m = (t₀ + t₁)/2 for the step to be second-order accurate:
/// - between two samples a, b (an IMU step, possibly cut by an earlier update at t₀ > t_a):
///     u(t_m) = u_a + (u_b − u_a) (t_m − t_a) / (t_b − t_a)                  (interpolated)
/// - past the last sample k (a range or baro update before sample k+1 has come):
///     u(t_m) = u_k + (u_k − u_{k−1}) (t_m − t_k) / (t_k − t_{k−1})          (extrapolated)
///   while t₁ lies within one IMU period of t_k and that period is not a gap; the latest reading
///   held otherwise.
/// The latest reading held instead lags the motion by half the step. With a range every other
/// IMU step that lag costs a simulated walk 3 cm and 0.03° of dead reckoning per 5 s, ten times
/// what a tactical IMU's noise does (docs/modular_estimator.md "Readings between IMU samples").

#include <Eigen/Core>
#include <optional>

#include "common/types.h"

namespace meshnav::estimator {

/// Accelerometer and gyro readings held over one propagation step.
struct ImuReading {
  Eigen::Vector3d acc_m_s2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_rad_s = Eigen::Vector3d::Zero();
};

/// The readings of samples `a`, `b` interpolated to the middle of [t0, t1] ⊆ [a.t, b.t]; `b`'s
/// when the two share a time.
inline ImuReading readingBetween(const ImuSample& a, const ImuSample& b, Timestamp t0, Timestamp t1) {
  const double span_s = (b.t - a.t).sec();
  if (span_s <= 0.0) return {b.acc_m_s2, b.gyro_rad_s};
  const double w = 0.5 * ((t0 - a.t).sec() + (t1 - a.t).sec()) / span_s;
  return {(1.0 - w) * a.acc_m_s2 + w * b.acc_m_s2, (1.0 - w) * a.gyro_rad_s + w * b.gyro_rad_s};
}

/// The readings over [t0, t1] after the last sample `last` (t0 ≥ last.t), extrapolated along
/// `prev` → `last` to the middle of the step when t1 − last.t is within the period
/// last.t − prev.t and that period is at most `max_period_s`; `last`'s readings held otherwise.
inline ImuReading readingPast(const ImuSample& last, const std::optional<ImuSample>& prev, Timestamp t0,
                              Timestamp t1, double max_period_s) {
  ImuReading r{last.acc_m_s2, last.gyro_rad_s};
  if (!prev) return r;
  const double period_s = (last.t - prev->t).sec();
  const double t0_s = (t0 - last.t).sec(), t1_s = (t1 - last.t).sec();
  if (period_s <= 0.0 || period_s > max_period_s || t0_s < 0.0 || t1_s > period_s) return r;
  const double w = 0.5 * (t0_s + t1_s) / period_s;
  r.acc_m_s2 += w * (last.acc_m_s2 - prev->acc_m_s2);
  r.gyro_rad_s += w * (last.gyro_rad_s - prev->gyro_rad_s);
  return r;
}

}  // namespace meshnav::estimator
