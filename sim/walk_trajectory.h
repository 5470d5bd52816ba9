#pragma once
/// @file walk_trajectory.h
/// @brief A person carrying the sensor rig by hand, walking laps of an ellipse around the hall:
/// no take-off, never landed, no barometer, attitude of a hand-held rig (not a quadrotor's).
///
/// Lap angle θ = θ₀ + s Θ π(t) (π the `SmoothProgress` of the walk: standing at the start and the
/// end, Θ from the walking speed v), ellipse centre c, semi-axes a, b. The heading follows the
/// walking direction, the tangent of the ellipse:
///   ψ_w = atan2(s b cos θ, −s a sin θ).
/// Gait at the step frequency f (≈ 1.8 Hz), scaled by the walking envelope e(t):
///   p_xy = c + [a cos θ, b sin θ] + A_l e sin(π f t + φ_l) [−sin ψ_w, cos ψ_w]   (lateral sway, f/2),
///   z = h₀ + A_h sin(2πt/P_h + φ_h) + A_b e sin(2π f t + φ_b)                     (vertical bob, f),
///   ψ = ψ_w + A_ψ e sin(π f t + φ_ψ),  θ_pitch = θ₀ + A_θ e sin(2π f t + φ_θ),  φ_roll = A_φ e sin(π f t + φ_r),
///   R_ItoG = R_z(ψ) R_y(θ_pitch) R_x(φ_roll).   Height 0.9–1.5 m.

#include <cstdint>

#include "sim/hall.h"
#include "sim/smooth_progress.h"
#include "sim/trajectory.h"

namespace meshnav::sim {

class WalkTrajectory : public Trajectory {
 public:
  /// Parameters drawn from `seed` to fit `hall` (path ≥ 0.75 m from the walls); `duration_s` ≥ 20 s.
  WalkTrajectory(const Hall& hall, double duration_s, uint64_t seed);
  TrajectoryState evaluate(double t_s) const override;
  double duration() const override { return duration_s_; }
  bool hasBarometer() const override { return false; }
  bool isHandCarried() const override { return true; }
  std::string kind() const override { return "walk"; }
  std::string toString() const override;
  double stepFrequency() const { return step_hz_; }

 private:
  double duration_s_;
  SmoothProgress walking_;
  Eigen::Vector2d center_m_;                  ///< c [m]
  double semi_a_m_ = 1, semi_b_m_ = 1;        ///< a, b [m]
  double theta0_rad_ = 0, direction_ = 1, total_angle_rad_ = 1;  ///< θ₀, s, Θ
  double speed_m_s_ = 1.1;                    ///< v [m/s]
  double step_hz_ = 1.8;                      ///< f [Hz]
  double height_m_ = 1.2, height_amp_m_ = 0.1, height_period_s_ = 30, height_phase_rad_ = 0;  ///< h₀, A_h, P_h, φ_h
  double bob_m_ = 0.025, sway_m_ = 0.02;      ///< A_b, A_l [m]
  double yaw_sway_rad_ = 0.03, pitch0_rad_ = 0, pitch_sway_rad_ = 0.03, roll_sway_rad_ = 0.04;
  double phase_rad_[5] = {0, 0, 0, 0, 0};     ///< φ_l, φ_b, φ_ψ, φ_θ, φ_r
};

}  // namespace meshnav::sim
