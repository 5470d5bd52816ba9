#pragma once
/// @file trajectory_jets.h
/// @brief Building blocks shared by the analytic trajectories: smooth steps as Taylor jets in t,
/// and the conversion of position/attitude jets into an exact `TrajectoryState`.
///
/// Smooth steps (u = normalized time, clamped to [0, 1]):
///   S(u) = 126u⁵ − 420u⁶ + 540u⁷ − 315u⁸ + 70u⁹  (smootherstep; S′…S⁗ vanish at both ends: C⁴)
///   I(u) = ∫₀ᵘ S = 21u⁶ − 60u⁷ + 67.5u⁸ − 35u⁹ + 7u¹⁰ for u ∈ [0,1], u − ½ for u > 1.
/// Attitude of a quadrotor (body z along the thrust, differential flatness):
///   z_I = (a − g_G)/‖a − g_G‖,  x_c = [cos ψ, sin ψ, 0],  y_I = (z_I × x_c)/‖z_I × x_c‖,
///   x_I = y_I × z_I,  R_ItoG = [x_I y_I z_I]   (needs p up to the 4th derivative for α).
/// Attitude of a hand-held rig from yaw ψ, pitch θ, roll φ:  R_ItoG = R_z(ψ) R_y(θ) R_x(φ).
/// Rates from the attitude jet: ω_I = vee(Rᵀ Ṙ), α_I = vee(Ṙᵀ Ṙ + Rᵀ R̈) (skew parts).

#include <algorithm>
#include <array>
#include <numbers>

#include "sim/hall.h"
#include "sim/random_stream.h"
#include "sim/taylor_jet.h"
#include "sim/trajectory_state.h"

namespace meshnav::sim {

inline constexpr double kPi = std::numbers::pi;

constexpr int kPositionJetOrder = 4;  ///< p, v, a, jerk, snap
constexpr int kAttitudeJetOrder = 2;  ///< R, Ṙ, R̈
using PositionJet = TaylorJet<kPositionJetOrder>;
using AttitudeJet = TaylorJet<kAttitudeJetOrder>;
using PositionJet3 = std::array<PositionJet, 3>;

/// Smootherstep S(u), clamped: 0 for u ≤ 0, 1 for u ≥ 1.
PositionJet smoothStep(const PositionJet& u);
/// I(u) = ∫₀ᵘ S(s) ds: 0 for u ≤ 0, u − ½ for u ≥ 1.
PositionJet smoothStepIntegral(const PositionJet& u);

/// The horizontal frame of a hall: unit vectors u along its longer side (x when the sides are
/// equal) and w along the shorter one, and the half lengths of both sides.
struct HallAxes {
  Eigen::Vector2d u = Eigen::Vector2d::UnitX(), w = Eigen::Vector2d::UnitY();
  double half_u_m = 0, half_w_m = 0;

  static constexpr double kWallMargin_m = 0.7;  ///< a pattern's reach stays this far from the walls

  static HallAxes of(const Hall& hall);
  /// How far a pattern centred in the hall may reach along u (w): the half length less the wall
  /// margin, at least `min_m` [m].
  double reachU(double min_m) const { return std::max(min_m, half_u_m - kWallMargin_m); }
  double reachW(double min_m) const { return std::max(min_m, half_w_m - kWallMargin_m); }
  /// x and y of the point c + a u + b w (c's z not used).
  std::array<PositionJet, 2> point(const Eigen::Vector3d& c, const PositionJet& a, const PositionJet& b) const;
};

/// A quadrotor's heading swinging around ψ₀: ψ = ψ₀ + A_ψ e sin(2πt/P_ψ + φ_ψ), e the pattern's
/// speed envelope (1 where not given).
struct HeadingWobble {
  double yaw0_rad = 0, amplitude_rad = 0, period_s = 20, phase_rad = 0;

  /// ψ₀, A_ψ ∈ [amplitude_lo, amplitude_hi], P_ψ ∈ [period_lo, period_hi], φ_ψ drawn in this order
  /// (ψ₀ and φ_ψ uniform in [−π, π]); the order is part of what a seed means.
  static HeadingWobble draw(RandomStream& rng, double amplitude_lo, double amplitude_hi, double period_lo,
                            double period_hi);
  PositionJet at(const PositionJet& t) const;
  PositionJet at(const PositionJet& t, const PositionJet& envelope) const;
};

/// State of a quadrotor at `t_s` from the position jets p_IinG(t) and the heading jet ψ(t) [rad].
TrajectoryState quadrotorState(double t_s, const PositionJet3& p_IinG, const PositionJet& yaw_rad);
/// State of a rigid body at `t_s` from p_IinG(t) and yaw/pitch/roll jets [rad] (R = R_z R_y R_x).
TrajectoryState yawPitchRollState(double t_s, const PositionJet3& p_IinG, const PositionJet& yaw_rad,
                                  const PositionJet& pitch_rad, const PositionJet& roll_rad);

}  // namespace meshnav::sim
