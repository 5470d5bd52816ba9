#pragma once
/// @file spiral_trajectory.h
/// @brief The analytic flight of the paper's scenario: landed on the pad, take-off to ~2 m, three
/// upward elliptic spirals to ~8 m, descent and landing at the start point, landed again.
///
/// Building blocks (u = normalized time, clamped to [0, 1]):
///   S(u) = 126u⁵ − 420u⁶ + 540u⁷ − 315u⁸ + 70u⁹  (smootherstep; S, S′…S⁗ vanish at both ends: C⁴)
///   I(u) = ∫₀ᵘ S = 21u⁶ − 60u⁷ + 67.5u⁸ − 35u⁹ + 7u¹⁰ for u ∈ [0,1], u − ½ for u > 1.
/// Spiral phase angle with smooth ramps of length T_r at t_a (start) and t_b = t_end − T_r:
///   θ(t) = θ₀ + s·Ω·T_r·[I((t−t_a)/T_r) − I((t−t_b)/T_r)],  Ω = 2π·turns/(t_b − t_a), s = ±1,
///   progress π(t) = (θ − θ₀)/(s·2π·turns) ∈ [0, 1], speed envelope e(t) = S((t−t_a)/T_r) − S((t−t_b)/T_r).
/// Position (ellipse centre c, semi-axes a_x, a_y, mid-flight shrink δ):
///   x = c_x + m a_x cos θ,  y = c_y + m a_y sin θ,  m = 1 − δ sin²(π·π(t)) + A_r e(t) sin(2πt/P_r + φ_r)
///   z = z_pad + (h₁ − z_pad) S((t−t_to)/T_to) + (h₂ − h₁) π(t) + A_z e(t) sin(2πt/P_z + φ_z)
///       − (h₂ − z_pad) S((t−t_ld)/T_ld)
/// so the pad c + [a_x cos θ₀, a_y sin θ₀] is both the start and the end point. Heading:
///   ψ(t) = ψ₀ + k_ψ (θ − θ₀) + A_ψ e(t) sin(2πt/P_ψ + φ_ψ).
/// Attitude of a quadrotor (body z along the thrust, differential flatness):
///   z_I = (a − g_G)/‖a − g_G‖, g_G = [0, 0, −9.81],  x_c = [cos ψ, sin ψ, 0],
///   y_I = (z_I × x_c)/‖z_I × x_c‖,  x_I = y_I × z_I,  R_ItoG = [x_I y_I z_I].
/// Position is C⁴ everywhere (also where the landed phases join), hence a is C²,
/// ω (which needs the jerk) C¹ and α (needs the snap) C⁰. All derivatives come from Taylor jets
/// (`taylor_jet.h`); smooth steps and the quadrotor attitude are shared (`trajectory_jets.h`).

#include <cstdint>
#include <string>

#include "sim/hall.h"
#include "sim/trajectory.h"

namespace meshnav::sim {

/// Shape and timing of the flight. Times in seconds from dataset start, lengths in metres.
struct TrajectoryOptions {
  // Timing [s]
  double takeoff_start_s = 5.0;       ///< t_to: end of the initial landed phase
  double takeoff_duration_s = 6.0;    ///< T_to: climb from the pad to hover height
  double spiral_start_s = 12.0;       ///< t_a: the spiral's angular ramp starts
  double spiral_ramp_s = 6.0;         ///< T_r: angular speed ramp-up/down length
  double spiral_end_s = 122.0;        ///< t_b + T_r: rotation has stopped
  double landing_start_s = 123.0;     ///< t_ld: descent starts
  double landing_duration_s = 12.0;   ///< T_ld
  double duration_s = 140.0;          ///< end of the sequence (landed since t_ld + T_ld)
  // Geometry [m]
  double pad_height_m = 0.12;         ///< z of the IMU while landed
  double hover_height_m = 2.0;        ///< h₁ after take-off
  double top_height_m = 7.7;          ///< h₂ at the end of the spirals
  double center_x_m = 0.3;            ///< ellipse centre c (the hall centre is near x = 0.45)
  double center_y_m = 0.0;
  double semi_axis_x_m = 1.5;         ///< a_x
  double semi_axis_y_m = 3.0;         ///< a_y
  double mid_shrink = 0.15;           ///< δ: relative radius reduction mid-flight
  double radial_wobble = 0.04;        ///< A_r: relative radius oscillation (excites the accelerometer)
  double radial_wobble_period_s = 6.0;    ///< P_r
  double radial_wobble_phase_rad = 0.0;   ///< φ_r
  double turns = 3.0;                 ///< number of spiral revolutions
  double theta0_rad = -1.5707963267948966;  ///< θ₀: pad on the ellipse
  double direction = 1.0;             ///< s = +1 counter-clockwise, −1 clockwise
  double z_wobble_amplitude_m = 0.15; ///< A_z
  double z_wobble_period_s = 11.0;    ///< P_z
  double z_wobble_phase_rad = 0.0;    ///< φ_z
  // Heading
  double yaw0_rad = 0.0;              ///< ψ₀ on the pad
  double yaw_follow = 0.5;            ///< k_ψ: share of the spiral turn the heading follows
  double yaw_wobble_amplitude_rad = 0.3;  ///< A_ψ
  double yaw_wobble_period_s = 23.0;  ///< P_ψ
  double yaw_wobble_phase_rad = 0.0;  ///< φ_ψ

  /// Nominal scenario with seed-dependent variations of radii, centre, pad, phases, heading and
  /// timing (seeds 1–12: twelve similar but different flights). All times are multiplied by
  /// `duration_scale` (1 = ~140 s).
  static TrajectoryOptions randomized(uint64_t seed, double duration_scale = 1.0);
  /// The same flight mapped from the paper's hall into `hall`: the ellipse centre moves with the
  /// hall (affine per axis), the semi-axes and the radial wobble scale with the hall's width and
  /// depth, the heights with (H − 0.5 m)/(H_paper − 0.5 m) (the pad height stays).
  TrajectoryOptions fittedTo(const Hall& hall) const;
  /// Throws std::invalid_argument naming the inconsistent field.
  void validate() const;
  /// Multi-line human-readable listing with units.
  std::string toString() const;
};

/// Evaluates the flight at any time t ∈ ℝ (before 0 / after the end it stays on the pad).
class SpiralTrajectory : public Trajectory {
 public:
  explicit SpiralTrajectory(const TrajectoryOptions& options);

  /// Exact state at `t_s`.
  TrajectoryState evaluate(double t_s) const override;
  /// True while the UAV rests on the pad (before take-off and after touch-down).
  bool isLanded(double t_s) const override;
  double duration() const override { return options_.duration_s; }
  double takeoffTime() const override { return options_.takeoff_start_s; }
  double touchdownTime() const override { return options_.landing_start_s + options_.landing_duration_s; }
  bool hasLandedPhase() const override { return true; }
  std::string kind() const override { return "spiral"; }
  std::string toString() const override { return options_.toString(); }
  /// IMU position on the pad (start = end).
  Eigen::Vector3d padPosition() const;
  const TrajectoryOptions& options() const { return options_; }

 private:
  TrajectoryOptions options_;
};

}  // namespace meshnav::sim
