#pragma once
/// @file hover_trajectory.h
/// @brief A UAV hovering in the middle of the hall with a small slow drift, already in the air
/// at the start of the sequence (no take-off, no landed phase).
///
/// Per axis i, two drift sinusoids around the hover point c:
///   p_i = c_i + A_i sin(2πt/P_i + φ_i) + B_i sin(2πt/Q_i + χ_i),
///   ψ = ψ₀ + A_ψ sin(2πt/P_ψ + φ_ψ),
/// attitude of a quadrotor from thrust and heading.

#include <cstdint>

#include "sim/hall.h"
#include "sim/trajectory.h"
#include "sim/trajectory_jets.h"

namespace meshnav::sim {

class HoverTrajectory : public Trajectory {
 public:
  /// Parameters drawn from `seed` (drift ≤ 0.35 m horizontally, ≤ 0.15 m vertically).
  HoverTrajectory(const Hall& hall, double duration_s, uint64_t seed);
  TrajectoryState evaluate(double t_s) const override;
  double duration() const override { return duration_s_; }
  std::string kind() const override { return "hover"; }
  std::string toString() const override;

 private:
  double duration_s_;
  Eigen::Vector3d center_m_;                 ///< c [m]
  Eigen::Vector3d amp1_m_, amp2_m_;          ///< A, B [m]
  Eigen::Vector3d period1_s_, period2_s_;    ///< P, Q [s]
  Eigen::Vector3d phase1_rad_, phase2_rad_;  ///< φ, χ [rad]
  HeadingWobble yaw_;
};

}  // namespace meshnav::sim
