#pragma once
/// @file trajectory.h
/// @brief Interface of every simulated motion of the IMU frame I in the hall frame G (z up).
///
/// Implementations are smooth analytic functions of time whose derivatives are exact (Taylor jets,
/// `taylor_jet.h`), so that the simulated IMU integrates back to the truth:
///   p_IinG(t) C⁴,  v = ṗ,  a = p̈,  R_ItoG(t) C²,  [ω_I]× = R_ItoGᵀ Ṙ_ItoG,  α_I = ω̇_I.
/// Times are seconds from the dataset start; the motion is defined for every t ∈ ℝ.

#include <string>

#include "sim/trajectory_state.h"

namespace meshnav::sim {

class Trajectory {
 public:
  static constexpr double kGravity_m_s2 = 9.81;  ///< g_G = [0, 0, −9.81] m/s²

  virtual ~Trajectory() = default;
  /// Exact state at `t_s` [s].
  virtual TrajectoryState evaluate(double t_s) const = 0;
  /// Length of the sequence [s].
  virtual double duration() const = 0;
  /// True while the vehicle rests on the ground (default: never).
  virtual bool isLanded(double /*t_s*/) const { return false; }
  /// End of the initial landed phase [s] (default 0: no landed phase).
  virtual double takeoffTime() const { return 0.0; }
  /// Start of the final landed phase [s] (default `duration()`: no landed phase).
  virtual double touchdownTime() const { return duration(); }
  /// False (the default) for motions that never rest on the ground (a hand-held walk, a flight
  /// that starts in the air): they get no flight_state.csv and no take-off pad prior.
  virtual bool hasLandedPhase() const { return false; }
  /// True for vehicles that carry a barometer (every flight; not the hand-held rig).
  virtual bool hasBarometer() const { return true; }
  /// Carried by hand at a roughly constant height: the setup then states that height
  /// (SystemSetup::carried_height, what the rig's user knows).
  virtual bool isHandCarried() const { return false; }
  /// Short kind name ("spiral", "walk", ...).
  virtual std::string kind() const = 0;
  /// One line with the motion's parameters and units.
  virtual std::string toString() const = 0;
};

}  // namespace meshnav::sim
