#pragma once
/// @file pose_interpolation.h
/// @brief Pose at an arbitrary time from a time-sorted pose history (linear in position, slerp in
/// orientation), as the calibrator and the evaluation need it.

#include <optional>
#include <vector>

#include "common/types.h"

namespace meshnav {

/// Interpolated pose at `t`; nullopt when `t` lies outside [front.t, back.t] by more than
/// `max_extrapolation` or when the bracketing samples are more than `max_gap` apart.
std::optional<PoseSample> interpolatePose(const std::vector<PoseSample>& sorted_poses, Timestamp t,
                                          Duration max_gap = Duration::fromSec(0.5),
                                          Duration max_extrapolation = Duration::fromSec(0.0));

/// Same for estimates (covariances are taken from the nearer sample).
std::optional<PoseEstimate> interpolateEstimate(const std::vector<PoseEstimate>& sorted, Timestamp t,
                                                Duration max_gap = Duration::fromSec(0.5));

/// Converts estimates to plain poses.
std::vector<PoseSample> toPoseSamples(const std::vector<PoseEstimate>& estimates);

}  // namespace meshnav
