#pragma once
/// @file flight_recorder.h
/// @brief The evaluation of a closed-loop flight whose parts run as processes (vehicle_sim
/// `--out`, docs/closed_loop.md "Over LCM"); free of LCM. It is fed the vehicle's truth at every
/// IMU instant and what is on the bus — POSE, CONTROL_STATUS (as ControlStatus), ANCHOR_INIT,
/// ANCHORS — and gives a ClosedLoopResult with the metrics of computeMetrics
/// (closed_loop_metrics.h), the same as the flight in one process.
///
/// A controller sample is a CONTROL_STATUS (the controller process with `--status-rate 0`
/// publishes one per update) with the truth at its time: the status of an update at t_k (an IMU
/// instant) and the vehicle's state at t_k. A status not newer than the previous sample (a
/// heartbeat repeating it) is not a new sample; one at a time without truth (a heartbeat before
/// the flight) is counted, not used.

#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

#include "closed_loop/closed_loop.h"
#include "closed_loop/closed_loop_metrics.h"
#include "controller/controller_node.h"

namespace meshnav::closed_loop {

class FlightRecorder {
 public:
  /// `setup`, `truth`, `pad`: the vehicle's (SimulatedVehicle).
  FlightRecorder(SystemSetup setup, Truth truth, Eigen::Vector3d pad);

  /// The vehicle's state at an IMU instant.
  void onTruth(Timestamp t, const Eigen::Vector3d& p_IinG, const Eigen::Quaterniond& q_ItoG, bool airborne);
  void onPose(const PoseEstimate& e) { result_.estimates.push_back(e); }
  void onControlStatus(const controller::ControlStatus& s);
  void onAnchorInit(const AnchorInit& a) { result_.anchor_inits.push_back(a); }
  void onAnchors(const std::vector<AnchorEstimate>& a) { result_.final_anchors = a; }

  /// The newest controller status (mode, failsafe events), if any.
  const controller::ControlStatus* lastStatus() const { return have_status_ ? &last_status_ : nullptr; }
  /// Statuses at a time without truth (not used).
  int64_t statusesWithoutTruth() const { return without_truth_; }

  /// The result with its metrics; `end.failsafe_events` and `end.mission_complete` are taken from
  /// the last CONTROL_STATUS when there is one.
  ClosedLoopResult finish(FlightEnd end);

 private:
  struct TruthSample {
    Eigen::Vector3d p;
    Eigen::Quaterniond q;
    bool airborne;
  };
  ClosedLoopResult result_;
  std::unordered_map<int64_t, TruthSample> truth_;
  controller::ControlStatus last_status_;
  bool have_status_ = false;
  std::optional<Timestamp> last_sample_t_;  ///< time of the newest sample
  int64_t without_truth_ = 0;
};

}  // namespace meshnav::closed_loop
