#pragma once
/// @file closed_loop_io.h
/// @brief The files of a closed-loop flight (docs/closed_loop.md, `meshnav fly --out DIR`):
///   closed_loop.yaml  metrics (tracking_rmse_m, estimation_rmse_m, max_estimation_error_m, crashed,
///                     landed_within_m, failsafe_events, ... and per anchor initial / final errors)
///   truth.csv         #t,tx,ty,tz,qx,qy,qz,qw at every controller step (TUM, as groundtruth.csv)
///   estimate.csv      every POSE (docs/formats.md, estimate.csv)
///   planned.csv       t,x,y,z,yaw,mode,phase,waypoint,thrust,wx,wy,wz,pose_age_s,cov_trace (setpoint and command)
///   anchors.csv       the estimator's final anchors;  calibration.yaml  the calibrator's results
///   setup.yaml        what the system knew

#include <string>

#include "closed_loop/closed_loop.h"

namespace meshnav::closed_loop {

/// Writes the files above into `dir` (created). `seed` and `mission_file` go into closed_loop.yaml.
/// Throws std::runtime_error naming the file that failed.
/// `with_calibration` false: no calibration.yaml (over LCM the calibrator process writes its own).
void writeClosedLoopOutputs(const ClosedLoopResult& result, const std::string& dir, uint64_t seed,
                            const std::string& mission_file, bool with_calibration = true);

/// closed_loop.yaml's text.
std::string metricsYaml(const ClosedLoopMetrics& m, uint64_t seed, const std::string& mission_file);

}  // namespace meshnav::closed_loop
