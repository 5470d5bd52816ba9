#pragma once
/// @file lawnmower_trajectory.h
/// @brief A UAV surveying the hall in a lawnmower (boustrophedon) pattern at constant height:
/// straight lanes along the long hall axis u, joined by short shifts along the short axis w,
/// then back to the pad in one diagonal move.
///
/// Every move is a smootherstep S (C⁴, at rest at both ends). With n lanes of length 2L at
/// spacing Δ, lane legs of T_l, shifts of T_s and the return of T_ret, starting at t_p0:
///   u(t) = −L + Σ_{i<n} (−1)ⁱ 2L S((t − a_i)/T_l) − u_end S((t − a_ret)/T_ret),
///   w(t) = −W + Σ_{i<n−1} Δ S((t − b_i)/T_s) − (n − 1)Δ S((t − a_ret)/T_ret),
/// with a_i = t_p0 + i (T_l + T_s), b_i = a_i + T_l, a_ret = a_{n−1} + T_l, u_end = u after the
/// last lane + L. Height z = z_pad + (h − z_pad) airborne(t), heading ψ = ψ₀ + A_ψ e(t) sin(2πt/P_ψ);
/// attitude of a quadrotor. The pad is the corner (−L, −W) of the survey area.

#include <cstdint>

#include "sim/hall.h"
#include "sim/pad_flight_trajectory.h"
#include "sim/trajectory_jets.h"

namespace meshnav::sim {

class LawnmowerTrajectory : public PadFlightTrajectory {
 public:
  /// Parameters drawn from `seed` to fit `hall` (≥ 0.7 m from the walls, ≥ 1 m below the ceiling).
  LawnmowerTrajectory(const Hall& hall, double duration_s, uint64_t seed);
  TrajectoryState evaluate(double t_s) const override;
  std::string kind() const override { return "lawnmower"; }
  std::string toString() const override;

 private:
  Eigen::Vector3d center_m_;                 ///< survey area centre (z = pad height) [m]
  HallAxes axes_;                            ///< long and short horizontal axes
  double half_length_m_ = 1, half_width_m_ = 1;  ///< L, W [m]
  int lanes_ = 2;                            ///< n
  double leg_s_ = 10, shift_s_ = 4, return_s_ = 15;  ///< T_l, T_s, T_ret [s]
  double cruise_height_m_ = 2;               ///< h [m]
  double yaw0_rad_ = 0, yaw_amplitude_rad_ = 0, yaw_period_s_ = 20;
};

}  // namespace meshnav::sim
