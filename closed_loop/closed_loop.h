#pragma once
/// @file closed_loop.h
/// @brief A deterministic closed loop in one process (issue 37, docs/closed_loop.md): the simulated
/// vehicle (sim/simulated_vehicle.h) → its sensors → the project's Pipeline (estimator, calibrator,
/// mission) → POSE → the controller (controller/controller_node.h) → the vehicle, in lock-step
/// simulated time.
///
/// Every integration step (1 kHz) the vehicle's due samples go to the pipeline in the canonical
/// input order (estimator_input.h); FLIGHT_STATE also to the controller. At every IMU sample (the
/// pipeline has just published the POSE of that sample) the controller runs once and its command
/// acts from that instant on. The controller sees POSE only (except in `pose_outages_s`, a drill
/// that withholds it); the truth goes to the evaluation alone.
///
/// Metrics (ClosedLoopMetrics): while airborne (the vehicle off the floor),
///   estimation error e_k = ‖p̂(t_k) − p(t_k)‖ at every POSE, RMSE and max;
///   tracking error ‖p(t_k) − p_ref(t_k)‖ of the truth against the planned setpoint at every
///   controller step of the take-off, the legs and the return (not the landing's descent, whose
///   vertical reference is a speed);
///   the landing: horizontal distance of the final truth position to the pad.

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/messages.h"
#include "common/types.h"
#include "controller/controller_node.h"
#include "controller/controller_options.h"
#include "mission/mission.h"
#include "pipeline/pipeline.h"
#include "sim/sensor_faults.h"
#include "sim/simulated_vehicle.h"

namespace meshnav::closed_loop {

struct ClosedLoopOptions {
  mission::Mission mission;                   ///< steps for the mission node + `flight` (required)
  sim::SimulatedVehicleOptions vehicle;       ///< seed in vehicle.sensors.seed; the pad comes from the flight
  controller::ControllerOptions controller;
  pipeline::PipelineOptions pipeline;         ///< estimator, calibrator (mission: set from `mission`)
  std::string calibrator_config;              ///< calibrator YAML ("" = built-in), σ_d from the setup
  double max_duration_s = 400.0;              ///< stop here whatever happened [s]
  double after_touchdown_s = 2.0;             ///< keep running after the landing [s]
  /// POSE withheld from the controller in these [from, to) windows [s] (failsafe drills, tests).
  std::vector<std::pair<double, double>> pose_outages_s;
  /// Sensor faults of a drill (IMU gaps, an anchor off, RANGE loss) between the vehicle and the
  /// pipeline (sim/sensor_faults.h); none by default.
  sim::SensorFaultOptions faults;
  /// Called about once per simulated second with the time [s] (progress).
  std::function<void(double)> progress;
};

/// One controller step, for the planned / flown / estimated paths.
struct ClosedLoopSample {
  double t_s = 0.0;
  Eigen::Vector3d p_true = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_true = Eigen::Quaterniond::Identity();
  bool airborne = false;
  controller::ControlStatus status;           ///< mode, phase, setpoint, command
};

struct AnchorResult {
  SensorId id = 0;
  double initial_error_m = -1.0;  ///< ANCHOR_INIT vs truth (−1: not calibrated)
  double final_error_m = -1.0;    ///< the estimator's last belief vs truth (−1: none)
};

struct ClosedLoopMetrics {
  double tracking_rmse_m = 0.0;
  double estimation_rmse_m = 0.0;
  double max_estimation_error_m = 0.0;
  bool crashed = false;
  std::string crash_reason;
  bool landed = false;              ///< resting on the floor at the end, controller `landed`
  bool mission_complete = false;    ///< landed after the whole plan
  double landed_within_m = -1.0;    ///< horizontal distance of the final position to the pad [m]
  int64_t failsafe_events = 0;
  double duration_s = 0.0;
  double flight_time_s = 0.0;       ///< airborne time [s]
  std::vector<AnchorResult> anchors;
  double anchors_initial_mean_m = -1.0;
  double anchors_final_mean_m = -1.0;
};

struct ClosedLoopResult {
  ClosedLoopMetrics metrics;
  std::vector<ClosedLoopSample> samples;   ///< at every controller step
  std::vector<PoseEstimate> estimates;     ///< every POSE
  std::vector<AnchorEstimate> final_anchors;
  std::vector<AnchorInit> anchor_inits;
  std::vector<calib::CalibrationResult> calibration;  ///< the calibrator's results
  SystemSetup setup;
  Truth truth;
  Eigen::Vector3d pad = Eigen::Vector3d::Zero();
  std::string estimator_summary;           ///< counters of the estimator at the end
  std::string faults = "none";             ///< the sensor faults flown (SensorFaultOptions::toString)
  int64_t imu_dropped = 0;                 ///< IMU samples the faults took away
  int64_t ranges_dropped = 0;              ///< ranges the faults took away (anchor off, loss)
};

/// Sets the vehicle's pad and heading from the mission's `flight`. Throws std::invalid_argument
/// when the mission has no `flight`, or a waypoint, the pad or the take-off height lies outside the
/// vehicle's hall (the file, line and key in the message).
void applyFlightPlan(const mission::Mission& mission, sim::SimulatedVehicleOptions& vehicle);

class ClosedLoop {
 public:
  /// Throws std::invalid_argument when the mission has no `flight`, or a waypoint, the pad or the
  /// take-off height lies outside the vehicle's hall (the file, line and key in the message).
  explicit ClosedLoop(ClosedLoopOptions options);
  ClosedLoopResult run();

 private:
  ClosedLoopOptions options_;
};

}  // namespace meshnav::closed_loop
