/// @file imu_propagation.cpp
/// @brief ImuPropagation: between samples, to a measurement's time, across gaps (imu_propagation.h).

#include "estimator/imu/imu_propagation.h"

#include <algorithm>
#include <cmath>

namespace meshnav::estimator {

namespace {

/// Discrete covariance of white specific-force noise (density² qa [m²/s³]) and angular-rate
/// noise (qw [rad²/s]) integrated over dt: velocity and attitude random walks, position the
/// integrated velocity noise (qa dt³/3, cross term qa dt²/2).
ImuMatrix whiteImuNoise(double qa, double qw, double dt) {
  ImuMatrix Q = ImuMatrix::Zero();
  const Eigen::Matrix3d I3 = Eigen::Matrix3d::Identity();
  Q.block<3, 3>(ImuErr::kP, ImuErr::kP) = I3 * qa * dt * dt * dt / 3.0;
  Q.block<3, 3>(ImuErr::kP, ImuErr::kV) = Q.block<3, 3>(ImuErr::kV, ImuErr::kP) = I3 * qa * dt * dt / 2.0;
  Q.block<3, 3>(ImuErr::kV, ImuErr::kV) = I3 * qa * dt;
  Q.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) = I3 * qw * dt;
  return Q;
}

}  // namespace

void ImuPropagation::toSample(FusionStrategy& f, const ImuSample& s, const Inputs& in) const {
  const Timestamp t0 = f.state().t;
  // Readings interpolated to the middle of [t0, s.t] (held when no earlier reading).
  const ImuReading u = in.last_imu ? readingBetween(*in.last_imu, s, t0, s.t) : ImuReading{s.acc_m_s2, s.gyro_rad_s};
  propagate(f, u, s.t, in);
}

void ImuPropagation::toTime(FusionStrategy& f, Timestamp t, const Inputs& in) const {
  if (in.next_imu && in.last_imu && in.next_imu->t >= t &&
      (in.next_imu->t - in.last_imu->t).sec() <= options_.max_dt_s) {
    propagate(f, readingBetween(*in.last_imu, *in.next_imu, f.state().t, t), t, in);
    return;
  }
  propagate(f, readingPast(*in.last_imu, in.prev_imu, f.state().t, t, options_.extrapolate_max_period_s), t, in);
}

void ImuPropagation::propagate(FusionStrategy& f, const ImuReading& u, Timestamp t, const Inputs& in) const {
  const Timestamp t0 = f.state().t;
  // Held readings beyond max_dt after the last sample: the part of the step in the gap.
  const Timestamp stale_from = in.last_imu ? std::max(t0, in.last_imu->t + Duration::fromSec(options_.max_dt_s)) : t;
  const std::string& mode = options_.gap_readings;
  if (stale_from < t && mode != "held") {  // the string only in a gap
    // In the gap no reading. "held" repeats the last one for the whole gap, which turns a drone's
    // momentary rotation rate into tens of degrees (docs/robustness.md, "IMU gaps"); "mean"
    // repeats the low-passed readings (a steady turn as held, an oscillation averaged out);
    // "still" takes the vehicle as keeping its velocity and attitude (a = 0 in G, ω = 0).
    if (stale_from > t0) step(f, u, stale_from, in.lambda);
    const ImuState& x = f.state().imu;
    const bool mean = mode == "mean" && in.mean_reading;
    // Acceleration in G (0 for "still") and angular rate, as the readings they would give.
    const Eigen::Vector3d a_G = mean ? in.mean_reading->acc_m_s2 : Eigen::Vector3d::Zero();
    ImuReading gap;
    gap.acc_m_s2 = x.bias_acc_m_s2 + x.q_ItoG.conjugate() * (a_G - in.g_G);
    // Turning about the vertical at the low-passed rate; no tilting (a vehicle's tilt swings
    // about level: integrating a low-passed tilt rate for seconds leaves the attitude tilted
    // after the gap, and gravity leaks into the position).
    const double yaw_rate = mean ? in.mean_reading->gyro_rad_s.z() : 0.0;
    gap.gyro_rad_s = x.bias_gyro_rad_s + x.q_ItoG.conjugate() * Eigen::Vector3d(0.0, 0.0, yaw_rate);
    step(f, gap, t, in.lambda);
  } else {
    step(f, u, t, in.lambda);
  }
  const double dt = (t - stale_from).sec();
  if (dt <= 0.0) return;
  // Their error as white noise (velocity and attitude random walk; position the integrated
  // velocity noise).
  f.addImuNoise(whiteImuNoise(std::pow(options_.gap_sigma_acc_m_s2, 2), std::pow(options_.gap_sigma_gyro_rad_s, 2), dt));
}

void ImuPropagation::step(FusionStrategy& f, const ImuReading& u, Timestamp t, double lambda) const {
  const Timestamp t0 = f.state().t;
  f.propagate(u.acc_m_s2, u.gyro_rad_s, t);
  // The IMU noise beyond its stated densities that the range innovations show (λ − 1 of it), and
  // an extrapolated reading's own excess (λ times its extra_noise_scale), in one addition.
  const double extra = lambda - 1.0 + lambda * u.extra_noise_scale;
  if (extra > 0.0 && t > t0)
    f.addImuNoise(whiteImuNoise(extra * std::pow(options_.acc_noise_density, 2),
                                extra * std::pow(options_.gyro_noise_density, 2), (t - t0).sec()));
}

void ImuPropagation::updateMean(std::optional<ImuReading>& mean, const ImuState& x, const ImuSample& s,
                                const std::optional<ImuSample>& previous, const Eigen::Vector3d& g_G) const {
  const Eigen::Vector3d a_G = x.q_ItoG * (s.acc_m_s2 - x.bias_acc_m_s2) + g_G;
  const Eigen::Vector3d w_G = x.q_ItoG * (s.gyro_rad_s - x.bias_gyro_rad_s);
  const double dt = previous ? (s.t - previous->t).sec() : 0.0;
  if (!mean || dt <= 0.0 || dt > options_.max_dt_s) {  // (re)start after a gap
    mean = ImuReading{a_G, w_G};
    return;
  }
  const double a = 1.0 - std::exp(-dt / options_.gap_mean_time_constant_s);
  mean->acc_m_s2 += a * (a_G - mean->acc_m_s2);
  mean->gyro_rad_s += a * (w_G - mean->gyro_rad_s);
}

}  // namespace meshnav::estimator
