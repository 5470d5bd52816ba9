#pragma once
/// @file helix_trajectory.h
/// @brief A UAV climbing a circular helix up to near the ceiling and back down (one up-and-down
/// sweep) with the heading along the circle's tangent.
///
/// With the pattern progress π(t) of `PadFlightTrajectory`, n turns and direction s = ±1:
///   θ = θ₀ + s 2π n π(t),  p_xy = c + r [cos θ, sin θ],
///   z = z_pad + (h₁ − z_pad) airborne(t) + (h₂ − h₁) ½ (1 − cos 2π π(t)),
///   ψ = θ + s π/2 (tangent direction),
/// attitude of a quadrotor from thrust and heading. The pad is c + r [cos θ₀, sin θ₀].

#include <cstdint>

#include "sim/hall.h"
#include "sim/pad_flight_trajectory.h"

namespace meshnav::sim {

class HelixTrajectory : public PadFlightTrajectory {
 public:
  /// Parameters drawn from `seed` to fit `hall` (≥ 0.7 m from the walls, ≥ 0.6 m below the ceiling).
  HelixTrajectory(const Hall& hall, double duration_s, uint64_t seed);
  TrajectoryState evaluate(double t_s) const override;
  std::string kind() const override { return "helix"; }
  std::string toString() const override;

 private:
  Eigen::Vector3d center_m_;        ///< c (z = pad height) [m]
  double radius_m_ = 1;             ///< r [m]
  double turns_ = 3;                ///< n
  double direction_ = 1;            ///< s
  double theta0_rad_ = 0;           ///< θ₀
  double low_height_m_ = 1.5;       ///< h₁ [m]
  double top_height_m_ = 5;         ///< h₂ [m]
};

}  // namespace meshnav::sim
