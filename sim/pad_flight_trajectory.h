#pragma once
/// @file pad_flight_trajectory.h
/// @brief Base of the generated UAV flights (figure 8, lawnmower, helix): landed on the
/// pad, vertical take-off, a horizontal pattern, vertical landing back on the pad, landed again.
///
/// With the smootherstep S (`trajectory_jets.h`) the height above the pad is
///   z(t) = z_pad + (h − z_pad) [S((t − t_to)/T_to) − S((t − t_ld)/T_ld)] + (pattern's own z)
/// and the pattern runs on `SmoothProgress(t_p0, T_r, t_p1)` with t_to + T_to < t_p0 < t_p1 < t_ld:
/// the pattern starts and ends at the pad's horizontal position at rest, so take-off and landing
/// are purely vertical and the flight lands where it took off.
/// Fractions of the duration T (at T = 140 s: landed 4.9 s, take-off 6.3 s, landing 9.8 s).

#include <algorithm>
#include <string>

#include "sim/hall.h"

#include "sim/smooth_progress.h"
#include "sim/trajectory.h"

namespace meshnav::sim {

struct PadFlightTiming {
  double takeoff_start_s = 4.9;     ///< t_to: end of the initial landed phase [s]
  double takeoff_duration_s = 6.3;  ///< T_to [s]
  double pattern_start_s = 12.2;    ///< t_p0 [s]
  double pattern_ramp_s = 5.6;      ///< T_r [s]
  double pattern_end_s = 124.3;     ///< t_p1 [s]
  double landing_start_s = 125.3;   ///< t_ld [s]
  double landing_duration_s = 9.8;  ///< T_ld [s]
  double duration_s = 140.0;        ///< T [s] (landed from t_ld + T_ld on)

  /// The phases as fixed fractions of `duration_s` (≥ 30 s), with minimum lengths of the
  /// take-off (3 s), ramps (2 s) and landing (4 s).
  static PadFlightTiming forDuration(double duration_s);
  /// Throws std::invalid_argument naming the inconsistent field.
  void validate() const;
  std::string toString() const;
};

/// Landed phases, take-off and landing of a pad flight; subclasses add the pattern (`evaluate`).
class PadFlightTrajectory : public Trajectory {
 public:
  static constexpr double kPadHeight_m = 0.12;  ///< z of the IMU while landed [m]

  explicit PadFlightTrajectory(const PadFlightTiming& timing);
  /// The pad in the middle of the hall: its centre at z = kPadHeight_m.
  static Eigen::Vector3d centralPad(const Hall& hall) {
    return Eigen::Vector3d(hall.center().x(), hall.center().y(), kPadHeight_m);
  }
  /// A cruise height of `share` of the hall's height, at least 1 m from floor and ceiling [m].
  static double cruiseHeight(const Hall& hall, double share) {
    return std::clamp(share * hall.size().z(), 1.0, hall.size().z() - 1.0);
  }
  bool isLanded(double t_s) const override { return t_s <= takeoffTime() || t_s >= touchdownTime(); }
  double duration() const override { return timing_.duration_s; }
  double takeoffTime() const override { return timing_.takeoff_start_s; }
  double touchdownTime() const override { return timing_.landing_start_s + timing_.landing_duration_s; }
  bool hasLandedPhase() const override { return true; }
  const PadFlightTiming& timing() const { return timing_; }

 protected:
  /// Share of the cruise height reached: S((t − t_to)/T_to) − S((t − t_ld)/T_ld) ∈ [0, 1].
  PositionJet airborne(const PositionJet& t) const;
  /// Progress π ∈ [0, 1] and speed envelope e of the pattern.
  const SmoothProgress& pattern() const { return pattern_; }

 private:
  PadFlightTiming timing_;
  SmoothProgress pattern_;
};

}  // namespace meshnav::sim
