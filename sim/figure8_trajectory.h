#pragma once
/// @file figure8_trajectory.h
/// @brief A UAV flying horizontal figure eights (lemniscate of Gerono) around the hall centre.
///
/// Loop angle θ(t) = 2π n π(t) (n loops, π the pattern progress of `PadFlightTrajectory`); with the
/// long hall axis u and the short one w (unit vectors), centre c at cruise height h:
///   p_xy = c + A sin θ · u + (B/2) sin 2θ · w,
///   z = z_pad + (h − z_pad) airborne(t) + A_z e(t) sin(2πt/P_z + φ_z),
///   ψ = ψ₀ + A_ψ e(t) sin(2πt/P_ψ + φ_ψ),
/// attitude of a quadrotor from thrust and heading. The pad is the crossing point c (θ = 0).

#include <cstdint>

#include "sim/hall.h"
#include "sim/pad_flight_trajectory.h"
#include "sim/trajectory_jets.h"

namespace meshnav::sim {

class Figure8Trajectory : public PadFlightTrajectory {
 public:
  /// Parameters drawn from `seed` to fit `hall` (≥ 0.6 m from the walls, ≥ 0.5 m below the ceiling).
  Figure8Trajectory(const Hall& hall, double duration_s, uint64_t seed);
  TrajectoryState evaluate(double t_s) const override;
  std::string kind() const override { return "figure8"; }
  std::string toString() const override;

 private:
  Eigen::Vector3d center_m_;                 ///< c (z = pad height) [m]
  HallAxes axes_;                            ///< long and short horizontal axes
  double amplitude_u_m_ = 0, amplitude_w_m_ = 0;  ///< A, B [m]
  double loops_ = 1;                         ///< n
  double cruise_height_m_ = 2;               ///< h [m]
  double z_amplitude_m_ = 0, z_period_s_ = 10, z_phase_rad_ = 0;
  HeadingWobble yaw_;
};

}  // namespace meshnav::sim
