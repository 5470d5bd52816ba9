#pragma once
/// @file truth_consistency.h
/// @brief Where the ground truth contradicts the recording's own gyro (a motion-capture dropout,
/// a marker swap): those stretches are left out of the evaluation instead of scoring the
/// estimate against a wrong pose.
///
/// The angle of the relative rotation over a window [t0, t1] does not depend on the frame it is
/// expressed in, so the truth (any body frame rigidly attached to the IMU) and the gyro must agree
/// on it without alignment or calibration:
///
///     θ_truth = ∠(q_truth(t0)⁻¹ q_truth(t1)),   θ_gyro = ∠(∏ Exp(ω_k Δt_k)),   |θ_truth − θ_gyro| ≤ tol.
///
/// What differs between them on a correct truth, over a window of T = 0.25 s: a gyro bias
/// (≤ 0.01 rad/s: 0.0025 rad), a scale error (1 % of the turn), a clock offset between truth and
/// IMU δt (STAR-loc's ~30 ms at angular accelerations up to 5 rad/s²: ≤ 0.04 rad), the truth's
/// orientation noise (≤ 1°: 0.02 rad). The tolerance 0.125 rad (7°, 0.5 rad/s over T) is about
/// three times their sum. Measured (2026-12-05): ISAS-Walk1 and MILUV ifo001 no window flagged;
/// STAR-loc loop2d-s1 6.52–6.77 and 7.04–7.27 s (truth 0.37 / 0.74 rad, gyro 0.17 / 0.13 rad:
/// its README's Vicon dropout at 6.4–7.3 s); MILUV ifo002 43.11–43.60 s (truth 3.0 rad, gyro
/// 0.18 rad: the truth turns half a circle in a quarter second).

#include <vector>

#include "common/types.h"

namespace meshnav::eval {

struct TruthFault {
  Timestamp t0, t1;              ///< the window (IMU sample times)
  double truth_angle_rad = 0.0;  ///< rotation angle of the truth over it
  double gyro_angle_rad = 0.0;   ///< of the integrated gyro
};

struct TruthCheckOptions {
  double window_s = 0.25;      ///< T [s]
  double tolerance_rad = 0.125;  ///< largest |θ_truth − θ_gyro| on a correct truth [rad]
  double max_truth_dt_s = 0.05;  ///< a window end whose truth samples are more than 2× this apart is not checked [s]
  double step_fraction = 0.25;   ///< windows start every step_fraction · T (they overlap) [-]
};

/// The stretches of `imu` (sorted by time) where the truth (sorted) disagrees with the gyro: windows
/// of T starting every step_fraction · T, overlapping ones that disagree merged into one fault.
std::vector<TruthFault> truthGyroFaults(const std::vector<PoseSample>& truth, const std::vector<ImuSample>& imu,
                                        const TruthCheckOptions& options = {});

/// Removes the truth samples inside the faults' windows (so an estimate there has no truth to be
/// compared with); returns how many were removed.
size_t dropTruthInFaults(std::vector<PoseSample>& truth, const std::vector<TruthFault>& faults);

}  // namespace meshnav::eval
