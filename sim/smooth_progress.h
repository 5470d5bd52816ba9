#pragma once
/// @file smooth_progress.h
/// @brief Progress of a periodic pattern (laps, loops, lanes) that starts and stops smoothly.
///
/// With the ramp length T_r, start t_a and t_b = t_end − T_r (I, S from `trajectory_jets.h`):
///   π(t) = T_r [I((t − t_a)/T_r) − I((t − t_b)/T_r)] / (t_b − t_a) ∈ [0, 1]   (progress),
///   e(t) = S((t − t_a)/T_r) − S((t − t_b)/T_r) ∈ [0, 1]                        (speed envelope),
/// so π̇ = e/(t_b − t_a): zero before t_a and after t_end, constant between the ramps; π is C⁵.

#include "sim/trajectory_jets.h"

namespace meshnav::sim {

class SmoothProgress {
 public:
  /// Throws std::invalid_argument unless t_end_s − t_start_s ≥ 2 ramp_s > 0.
  SmoothProgress(double t_start_s, double ramp_s, double t_end_s);
  /// π(t) ∈ [0, 1].
  PositionJet progress(const PositionJet& t) const;
  /// e(t) ∈ [0, 1]: 1 at full speed, 0 at rest.
  PositionJet envelope(const PositionJet& t) const;
  double start() const { return t_start_s_; }
  double end() const { return t_end_s_; }

 private:
  double t_start_s_, ramp_s_, t_end_s_;
};

}  // namespace meshnav::sim
