#pragma once
/// @file imu_simulator.h
/// @brief Flight-controller IMU: specific force and angular rate of the analytic trajectory with
/// white noise and bias random walk.
///
/// Measurement at t_k = k·Δt (Δt = 1/rate):
///   f_m = R_ItoGᵀ (a_G − g_G) + b_a + n_a,   ω_m = ω_I + b_g + n_g,   g_G = [0, 0, −9.81] m/s²
/// with discrete white noise n ~ N(0, σ_d²), σ_d = σ_c / √Δt (σ_c: noise density), and biases that
/// start at b(0) ~ N(0, σ_b0²) and random-walk b_{k+1} = b_k + σ_w √Δt · N(0, 1) (σ_w: bias rw density).
///
/// Rotor vibration (issue 36 item 7): while a rotorcraft is airborne (not landed, not carried by
/// hand), its IMU shakes with the rotors. Per axis i and sensor, two tones at the rotor frequencies
/// f_1, f_2 ~ U(rotor_min_hz, rotor_max_hz) (drawn once per sequence; the phases per axis):
///   f_m += A_f,i (sin(2π f_1 t + φ_1i) + sin(2π f_2 t + φ_2i)) / √2,  ω_m likewise with A_ω,i,
/// A_i ~ U(0.5, 1.5) · vibration_acc_m_s2 (vibration_gyro_rad_s), so each axis has an RMS of about
/// A_i / √2. Sampled at 200 Hz, rotor tones of 110–170 Hz alias to 30–90 Hz, far from 0 Hz:
/// zero-mean over a few samples, a tone integrates to a velocity offset of at most
/// A / (2π f_alias), a few mm/s (its phase where an integration starts; 0.09 m over 10 s at the
/// default scale, against 2.5 m for the default accelerometer bias σ alone). It leaves the
/// navigation solution alone, but a hover or a straight leg no longer reads like rest, as it
/// does on real hardware. The densities written to setup.yaml stay the sensor's own (the stillness
/// detector's thresholds scale with them). Off (0) in noiseless(); its draws come from a stream
/// of their own, so every other draw is the same with or without it.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/types.h"
#include "sim/random_stream.h"
#include "sim/trajectory.h"

namespace meshnav::sim {

struct ImuNoiseOptions {
  double rate_hz = 200.0;                  ///< sample rate [Hz]
  double acc_noise_density = 2e-3;         ///< σ_c accelerometer [m/s²/√Hz]
  double gyro_noise_density = 2e-4;        ///< σ_c gyroscope [rad/s/√Hz]
  double acc_bias_rw = 3e-3;               ///< σ_w accelerometer bias random walk [m/s³/√Hz]
  double gyro_bias_rw = 2e-5;              ///< σ_w gyroscope bias random walk [rad/s²/√Hz]
  double acc_bias_initial_sigma = 0.05;    ///< σ of b_a(0) [m/s²]
  double gyro_bias_initial_sigma = 0.005;  ///< σ of b_g(0) [rad/s]
  /// Axis errors of real MEMS parts (issue 34 item 4), both sensors, drawn once per sequence:
  /// a reading is T ideal + b + n with T = I + diag(s) + the off-diagonal terms m_ij (axes that
  /// are scaled and not orthogonal to the body's), s_i ~ N(0, scale_sigma²) [-],
  /// m_ij ~ N(0, misalignment_sigma_rad²) [rad]. 0: exact axes (the default; draws nothing).
  double scale_sigma = 0.0;
  double misalignment_sigma_rad = 0.0;
  /// Rotor vibration while airborne (above): amplitude scale of the specific force [m/s²] and of
  /// the angular rate [rad/s] per axis, rotor frequency range [Hz]. 0: none (`--vibration 0`).
  double vibration_acc_m_s2 = 0.6;
  double vibration_gyro_rad_s = 0.03;
  double rotor_min_hz = 110.0;
  double rotor_max_hz = 170.0;

  /// All noise and biases zero (ideal IMU).
  static ImuNoiseOptions noiseless();
  /// Figures of an IMU grade (`--imu-grade`), 200 Hz:
  ///   grade     acc σ_c       gyro σ_c      acc bias rw   gyro bias rw   b_a(0) σ   b_g(0) σ
  ///   consumer  6e-3          6e-4          1e-2          1e-4           0.1        0.01
  ///   fc        2e-3          2e-4          3e-3          2e-5           0.05       0.005   (the defaults)
  ///   tactical  5e-4          3e-5          3e-4          1e-6           0.01       0.0005
  /// Throws std::invalid_argument for another name.
  static ImuNoiseOptions forGrade(const std::string& grade);
  std::string toString() const;
};

/// Samples the IMU along a trajectory.
class ImuSimulator {
 public:
  ImuSimulator(const ImuNoiseOptions& options, uint64_t seed);

  /// The ideal (noise-free, bias-free) reading for one state: f_I = Rᵀ(a − g), ω_I.
  static ImuSample ideal(const TrajectoryState& state);

  /// Readings at t_k = k/rate for t_k ∈ [0, t_end_s] (`start` then `sample` per t_k).
  std::vector<ImuSample> simulate(const Trajectory& trajectory, double t_end_s);

  /// Step-wise sampling (a closed-loop vehicle, sim/closed_loop_vehicle.h): draws the initial
  /// biases, the axes and the rotor tones exactly as `simulate` does. `rotorcraft`: the vehicle's
  /// rotors shake the IMU while airborne (false: a hand-carried rig).
  void start(bool rotorcraft);
  /// The next reading, for the exact state at its time (the caller keeps the 1/rate grid): the bias
  /// random-walk step (not before the first sample) and the noise, plus the rotor vibration while
  /// `airborne`. The same draws in the same order as `simulate`: a trajectory sampled this way
  /// gives `simulate`'s readings bit for bit. Calls `start(true)` first if it was not called.
  ImuSample sample(const TrajectoryState& state, bool airborne);

  /// Bias at the first sample (after `simulate`) [m/s², rad/s].
  const Eigen::Vector3d& initialAccBias() const { return bias_acc0_; }
  const Eigen::Vector3d& initialGyroBias() const { return bias_gyro0_; }
  /// The axis matrices T of the accelerometer and the gyroscope (after `simulate`; identity when
  /// the options draw none).
  const Eigen::Matrix3d& accAxes() const { return acc_T_; }
  const Eigen::Matrix3d& gyroAxes() const { return gyro_T_; }
  /// Bias at the last sample (after `simulate`).
  const Eigen::Vector3d& finalAccBias() const { return bias_acc_; }
  const Eigen::Vector3d& finalGyroBias() const { return bias_gyro_; }

 private:
  ImuNoiseOptions options_;
  uint64_t seed_;
  Eigen::Vector3d bias_acc0_ = Eigen::Vector3d::Zero(), bias_gyro0_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d bias_acc_ = Eigen::Vector3d::Zero(), bias_gyro_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d acc_T_ = Eigen::Matrix3d::Identity(), gyro_T_ = Eigen::Matrix3d::Identity();
  // Step-wise state (start / sample).
  std::optional<RandomStream> rng_noise_, rng_bias_;
  int64_t n_sampled_ = 0;
  bool rotorcraft_ = false;
  std::array<double, 2> rotor_hz_{0.0, 0.0};
  Eigen::Matrix<double, 3, 2> phase_acc_ = Eigen::Matrix<double, 3, 2>::Zero(), phase_gyro_ = phase_acc_;
  Eigen::Vector3d amp_acc_ = Eigen::Vector3d::Zero(), amp_gyro_ = Eigen::Vector3d::Zero();
};

}  // namespace meshnav::sim
