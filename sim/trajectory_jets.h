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

#include <array>

#include "sim/taylor_jet.h"
#include "sim/trajectory_state.h"

namespace meshnav::sim {

constexpr int kPositionJetOrder = 4;  ///< p, v, a, jerk, snap
constexpr int kAttitudeJetOrder = 2;  ///< R, Ṙ, R̈
using PositionJet = TaylorJet<kPositionJetOrder>;
using AttitudeJet = TaylorJet<kAttitudeJetOrder>;
using PositionJet3 = std::array<PositionJet, 3>;

/// Smootherstep S(u), clamped: 0 for u ≤ 0, 1 for u ≥ 1.
PositionJet smoothStep(const PositionJet& u);
/// I(u) = ∫₀ᵘ S(s) ds: 0 for u ≤ 0, u − ½ for u ≥ 1.
PositionJet smoothStepIntegral(const PositionJet& u);

/// State of a quadrotor at `t_s` from the position jets p_IinG(t) and the heading jet ψ(t) [rad].
TrajectoryState quadrotorState(double t_s, const PositionJet3& p_IinG, const PositionJet& yaw_rad);
/// State of a rigid body at `t_s` from p_IinG(t) and yaw/pitch/roll jets [rad] (R = R_z R_y R_x).
TrajectoryState yawPitchRollState(double t_s, const PositionJet3& p_IinG, const PositionJet& yaw_rad,
                                  const PositionJet& pitch_rad, const PositionJet& roll_rad);

}  // namespace meshnav::sim
