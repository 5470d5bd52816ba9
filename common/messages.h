#pragma once
/// @file messages.h
/// @brief Plain structs for the status and command channels (ESTIMATOR_STATUS, ESTIMATOR_CMD,
/// CALIB_CMD, CALIB_STATUS, MISSION_STATUS). They mirror the LCM types field by field; the
/// libraries use only these, the processes convert at the edge.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "common/types.h"

namespace meshnav {

/// Per-instance (sensor) state in the estimator.
struct InstanceStatus {
  SensorId id = 0;
  std::string type;        ///< "imu", "baro", "tag", "anchor"
  int64_t n_updates = 0;   ///< measurements fused through this instance
  int64_t n_rejected = 0;  ///< measurements gated (χ²) or rejected for this instance
};

/// ESTIMATOR_STATUS: health of the estimator, published at ≥ 1 Hz (the heartbeat).
struct EstimatorStatus {
  Timestamp t;                 ///< filter time (newest processed measurement)
  int64_t wall_utime = 0;      ///< wall clock at publication [µs since Unix epoch]
  bool initialized = false;
  std::string strategy;        ///< "centralized", "dp", "dah"
  std::vector<InstanceStatus> instances;
  /// Counters: "out_of_sequence", "rejected_too_old", "gated_range", "unknown_id", "bad_input", ...
  std::map<std::string, int64_t> counters;
  /// Mean step durations [µs] by step type: "propagate", "range_update", "baro_update", "zupt".
  std::map<std::string, double> mean_step_us;
  /// "initializing", "ok", "degraded" or "lost" (estimator/health/health_monitor.h).
  std::string health = "initializing";
  /// Why the health is not ok, or what initialization waits for.
  std::string health_reason;
  double sigma_p_max_m = 0.0;                            ///< largest principal position σ [m]
  Eigen::Vector3d weak_axis_G = Eigen::Vector3d::Zero(); ///< its direction (unit, G)
  double sigma_yaw_deg = 0.0;                            ///< yaw σ [deg]
  /// The UWB stamps' delay against the IMU clock in use (a range stamped t was measured at the
  /// IMU-clock instant t − this) [s], and its σ [s] (0: setup.yaml's constant, not a state).
  double uwb_clock_offset_s = 0.0;
  double uwb_clock_offset_sigma_s = 0.0;
};

/// ESTIMATOR_CMD: run-time control of the instance set.
struct EstimatorCommand {
  enum class Action : int8_t { AddAnchor = 0, RemoveInstance = 1, Reset = 2 };
  Timestamp t;
  Action action = Action::AddAnchor;
  SensorId id = 0;        ///< instance concerned
  AnchorInit anchor;      ///< for AddAnchor: position, covariance, bias dictionary
  /// The anchor AddAnchor adds: `anchor` with the command's id (when set) and time.
  AnchorInit anchorToAdd() const {
    AnchorInit a = anchor;
    a.id = id ? id : a.id;
    a.t = t;
    return a;
  }
};

/// CALIB_CMD: what the calibrator should do.
struct CalibCommand {
  enum class Action : int8_t { Collect = 0, Calibrate = 1, Abort = 2 };
  Timestamp t;
  Action action = Action::Calibrate;
  std::vector<SensorId> anchors;  ///< empty: every unknown anchor seen
};

/// One anchor in CALIB_STATUS.
struct CalibAnchorStatus {
  SensorId id = 0;
  std::string state;      ///< "collecting", "calibrated", "refused"
  int64_t n_ranges = 0;   ///< ranges collected involving this anchor
  int32_t n_refs = 0;     ///< distinct reference devices
  std::string reason;     ///< refusal reason, what automatic calibration waits for, or ""
};

/// CALIB_STATUS: progress and refusals of the calibrator, also its heartbeat.
struct CalibStatus {
  Timestamp t;
  int64_t wall_utime = 0;
  std::vector<CalibAnchorStatus> anchors;
  std::map<std::string, int64_t> counters;
};

/// MISSION_STATUS: the mission sequencer's progress, also its heartbeat.
struct MissionStatus {
  Timestamp t;
  int64_t wall_utime = 0;
  int32_t step_index = -1;    ///< index of the last executed step (-1: none yet)
  int32_t n_steps = 0;
  std::string text;           ///< human-readable state
};

}  // namespace meshnav
