#pragma once
/// @file closed_loop_metrics.h
/// @brief The metrics of a closed-loop flight (ClosedLoopMetrics, closed_loop.h), computed the same
/// way for the flight in one process (ClosedLoop) and over LCM (FlightRecorder in vehicle_sim):
///   estimation error e_k = ‖p̂(t_k) − p(t_k)‖ at the first POSE of every time t_k with the vehicle
///   airborne (RMSE and max); tracking error ‖p(t_k) − p_ref(t_k)‖ at every controller sample that
///   is airborne, flying, in phase takeoff|waypoints|return; the landing's horizontal distance to
///   the pad; the anchors' ANCHOR_INIT and final errors against the truth.

#include <cstdint>
#include <string>
#include <unordered_map>

#include <Eigen/Core>

#include "closed_loop/closed_loop.h"

namespace meshnav::closed_loop {

/// The truth at an IMU instant.
struct TruthAt {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  ///< position of I in G [m]
  bool airborne = false;                        ///< off the floor
};
using TruthTimeline = std::unordered_map<int64_t, TruthAt>;  ///< by time [µs]

/// How the flight ended.
struct FlightEnd {
  bool crashed = false;
  std::string crash_reason;
  bool landed = false;              ///< on the floor and the controller in `landed`
  bool mission_complete = false;
  int64_t failsafe_events = 0;
  Eigen::Vector3d p_end = Eigen::Vector3d::Zero();  ///< final true position [m]
  double duration_s = 0.0;
};

/// The metrics of `r` (samples, estimates, anchor_inits, final_anchors, truth, pad) with the truth
/// at the IMU instants and the end.
ClosedLoopMetrics computeMetrics(const ClosedLoopResult& r, const TruthTimeline& truth_at, const FlightEnd& end);

}  // namespace meshnav::closed_loop
