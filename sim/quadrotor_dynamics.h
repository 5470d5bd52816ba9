#pragma once
/// @file quadrotor_dynamics.h
/// @brief A quadrotor's translational and rotational dynamics for closed-loop flights (issue 37,
/// docs/closed_loop.md): the vehicle the controller flies, sampled by the existing sensor models.
///
/// State: p_IinG, v_IinG, R_ItoG, ω_IinI, the actual mass-normalized collective thrust T [m/s²].
/// Input (QuadrotorCommand): commanded thrust T_c [m/s²] and body rates ω_c [rad/s]. The rotors and
/// the rate loop of the flight controller are first-order lags,
///   Ṫ = (T_c − T)/τ_T,   ω̇ = (ω_c − ω)/τ_ω,
/// translation with gravity and linear drag on the air-relative velocity (wind w_G),
///   ṗ = v,   v̇ = R_ItoG e_z T + g_G − k_d (v − w_G),   g_G = [0, 0, −9.81] m/s²,
/// attitude Ṙ_ItoG = R_ItoG [ω]×. T_c is clamped to [0, max_thrust], each |ω_c,i| to max_rate.
///
/// Integration at a fixed step Δt (`integration_rate_hz`): the lags exactly
/// (x ← x_c + (x − x_c) e^{−Δt/τ}), the attitude with the exponential map of the mean rate
/// R ← R Exp(½(ω_k + ω_{k+1}) Δt), the velocity with the trapezoid of the accelerations at both ends
/// and the position with p ← p + v Δt + (2 a_k + a_{k+1}) Δt²/6 — exact for a constant rate and
/// for an acceleration linear over the step (hover, free fall, constant yaw rate).
///
/// Wind (optional, `gust_sigma_m_s` > 0): w_G = wind_mean + a first-order Gauss–Markov gust per axis,
/// w_{k+1} = ρ w_k + σ √(1 − ρ²) n,  ρ = e^{−Δt/τ_g}, from a seeded RandomStream ("wind_gusts").
///
/// Ground and walls: the IMU frame cannot go below the pad height z_pad (the floor) nor leave the
/// hall box. Touching the floor with a downward speed above `crash_speed_m_s` (or a wall with a
/// speed towards it above it) is a crash: the vehicle stops there and stays crashed. A slower
/// touch-down rests on the floor: v = 0, roll and pitch levelled (yaw kept), ω = 0, until the
/// thrust's vertical part exceeds g (take-off). While resting the vehicle is `landed()`.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>

#include <yaml-cpp/yaml.h>

#include "sim/random_stream.h"
#include "sim/trajectory_state.h"

namespace meshnav::sim {

struct QuadrotorOptions {
  double integration_rate_hz = 1000.0;   ///< fixed integration step 1/Δt [Hz]
  double thrust_time_constant_s = 0.03;  ///< τ_T: motor lag of the collective thrust [s]
  double rate_time_constant_s = 0.04;    ///< τ_ω: lag of the body rates behind their command [s]
  double drag_per_s = 0.3;               ///< k_d: linear drag on the air-relative velocity [1/s]
  double max_thrust_m_s2 = 20.0;         ///< largest mass-normalized collective thrust [m/s²]
  double max_rate_rad_s = 3.0;           ///< largest commanded body rate per axis [rad/s]
  double crash_speed_m_s = 1.0;          ///< floor / wall contact faster than this is a crash [m/s]
  double pad_height_m = 0.12;            ///< z of the IMU frame while resting on the floor [m]
  Eigen::Vector3d wind_mean_m_s = Eigen::Vector3d::Zero();  ///< mean wind in G [m/s]
  double gust_sigma_m_s = 0.0;           ///< σ of the gust per axis (0: no gusts) [m/s]
  double gust_time_constant_s = 2.0;     ///< τ_g of the gusts [s]
  Eigen::Vector3d hall_min_m{-2.5, -4.2, 0.0};  ///< hall box (walls, floor) in G [m]
  Eigen::Vector3d hall_max_m{3.0, 4.2, 8.2};

  /// Reads the keys above from a YAML map (`where` names it in messages); unknown keys and bad
  /// values are refused with the file and key.
  static QuadrotorOptions fromYaml(const YAML::Node& node, const std::string& where);
  /// Throws std::invalid_argument naming the key.
  void validate() const;
  std::string toString() const;
};

/// What the vehicle is told by its controller (the flight controller's inner loop input).
struct QuadrotorCommand {
  double thrust_m_s2 = 0.0;                               ///< collective thrust / mass [m/s²]
  Eigen::Vector3d w_IinI = Eigen::Vector3d::Zero();       ///< commanded body rates in I [rad/s]
};

class QuadrotorDynamics {
 public:
  /// Resting on the pad at `p_IinG` (z is set to the pad height) with heading `yaw_rad`, motors off.
  QuadrotorDynamics(const QuadrotorOptions& options, const Eigen::Vector3d& p_IinG, double yaw_rad,
                    uint64_t seed = 1);

  /// Sets the whole state (tests; airborne unless resting on the floor at zero speed).
  void setState(const Eigen::Vector3d& p_IinG, const Eigen::Vector3d& v_IinG, const Eigen::Matrix3d& R_ItoG,
                const Eigen::Vector3d& w_IinI, double thrust_m_s2);
  void setCommand(const QuadrotorCommand& command);
  /// One integration step Δt.
  void step();
  /// Steps until the time reaches `t_s` (at least nothing; steps on the Δt grid).
  void stepUntil(double t_s);

  double time() const { return static_cast<double>(k_) * dt_; }
  int64_t stepIndex() const { return k_; }
  double stepSize() const { return dt_; }
  /// The exact kinematic state now: p, v, a = v̇, R, q, ω, α = ω̇, yaw — what ImuSimulator::ideal
  /// turns into the IMU's specific force and rate.
  TrajectoryState state() const;
  double thrust() const { return thrust_; }
  const Eigen::Vector3d& wind() const { return wind_G_; }
  bool landed() const { return landed_; }
  bool crashed() const { return crashed_; }
  /// Speed [m/s] at the crash (0 if none) and what was hit ("floor", "wall").
  double crashSpeed() const { return crash_speed_; }
  const std::string& crashReason() const { return crash_reason_; }
  const QuadrotorOptions& options() const { return options_; }

 private:
  /// v̇ for a state (landed: 0).
  Eigen::Vector3d acceleration(const Eigen::Matrix3d& R, double thrust, const Eigen::Vector3d& v) const;
  void contact();

  QuadrotorOptions options_;
  double dt_;
  int64_t k_ = 0;
  Eigen::Vector3d p_ = Eigen::Vector3d::Zero(), v_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d w_ = Eigen::Vector3d::Zero();
  double thrust_ = 0.0;
  QuadrotorCommand cmd_;
  Eigen::Vector3d wind_G_ = Eigen::Vector3d::Zero(), gust_G_ = Eigen::Vector3d::Zero();
  RandomStream rng_wind_;
  bool landed_ = true;
  bool crashed_ = false;
  double crash_speed_ = 0.0;
  std::string crash_reason_;
};

}  // namespace meshnav::sim
