#pragma once
/// @file pipeline.h
/// @brief The whole system in one process (`meshnav run`, docs/architecture.md): the estimator, the
/// calibrator and the mission sequencer node classes wired as the processes are over LCM
/// (RANGE → estimator and calibrator, POSE/ANCHORS → calibrator and mission, CALIB_CMD,
/// ANCHOR_INIT, ESTIMATOR_CMD, CALIB_STATUS), but deterministic: every message a node emits is
/// queued and delivered in FIFO order after the node returns, exactly once, never re-entrantly.
///
/// **A fleet** (`meshnav_run --fleet`, docs/fleet.md): several vehicles share one anchor map. Each
/// vehicle has its own estimator node (its own setup: tags, IMU, baro); one calibrator takes the
/// ranges and poses of every vehicle (a pose history per vehicle) and one mission drives it. An
/// ANCHOR_INIT goes to every vehicle's estimator, with the pair biases of the other vehicles' tags
/// left out (and their rows of the joint covariance). ANCHORS towards the calibrator: per anchor the
/// belief with the smallest covariance trace among the vehicles' latest. ESTIMATOR_CMD goes to every
/// vehicle; the mission hears the first vehicle's ESTIMATOR_STATUS. A single vehicle is a fleet of
/// one, vehicle 0. A range of a vehicle's dataset to another vehicle's tag goes nowhere (counted,
/// "inter_vehicle_range:NAME" in `diagnostics()`): relative ranging between vehicles is not modelled.
/// An anchor–anchor range in several vehicles' datasets (the same time and pair: one mesh heard by
/// all) reaches the calibrator once; each estimator fuses its own dataset's.

#include <deque>
#include <functional>
#include <map>
#include <string>
#include <memory>
#include <optional>
#include <set>
#include <tuple>
#include <variant>
#include <vector>

#include "calibrator/calibrator_options.h"
#include "calibrator/node/calibrator_node.h"
#include "calibrator/node/calibrator_node_options.h"
#include "common/diagnostics.h"
#include "common/messages.h"
#include "common/setup.h"
#include "estimator/core/estimator_options.h"
#include "estimator/node/estimator_input.h"
#include "estimator/node/estimator_node.h"
#include "mission/mission.h"
#include "mission/mission_node.h"
#include "pipeline/peer_range_router.h"

namespace meshnav::pipeline {

class FleetCalibratorFeed;
class PeerRangeFeed;

struct PipelineOptions {
  estimator::EstimatorOptions estimator;
  calib::CalibratorOptions calibrator;
  calib::CalibratorNodeOptions calibrator_node;
  /// Mission steps; without one, new anchors are collected and calibrated automatically
  /// (calibrator_node.auto_mode is forced on).
  std::optional<mission::Mission> mission;
  bool calibration_enabled = true;     ///< false: no calibrator (known anchors only)
  double pose_to_calibrator_hz = 50.0; ///< POSE decimation towards the calibrator (0: every pose) [Hz]
  /// The calibrator's tag poses: the filter's POSE (false), or each of them replaced by its
  /// fixed-lag smoothed twin once that comes, lag_s later (true; issue 35 item 3, docs/smoother.md
  /// "Calibration on the smoothed path").
  bool calibrator_on_smoothed = false;
  /// A fleet's ranges between two vehicles' tags: fused (true) as a range to the other vehicle's
  /// estimated tag (docs/fleet.md "Inter-vehicle ranges"), or counted and dropped (false).
  bool inter_vehicle_ranges = true;
  /// Which vehicle fuses an inter-vehicle range (PeerRangeRouter; docs/decisions/016-fleet-sharing.md).
  PeerRangeRoutingOptions peer_routing;
  /// Analysis only, never a default (meshnav_run --peer-truth, docs/fleet.md "What the data
  /// allows"): the true pose of vehicle `vehicle` at `t` (nullopt: none). When set, each
  /// inter-vehicle range is fused in **both** vehicles, each with the other's true tag as an exact
  /// point (zero covariance): the bound of what the tag-to-tag ranges can give.
  std::function<std::optional<PoseSample>(size_t vehicle, Timestamp t)> peer_truth;
};

/// One vehicle of a fleet: a name (its output folder) and its setup. The anchors of every vehicle's
/// setup must be the fleet's shared map (`mergeFleetSetups`, fleet.h).
struct Vehicle {
  std::string name;
  SystemSetup setup;
};

/// What the pipeline emits (the channels a logger would record); the per-vehicle ones say whose
/// (the vehicle's index in the constructor's list, 0 for a single vehicle).
struct PipelineSinks {
  std::function<void(size_t vehicle, const PoseEstimate&)> pose;
  /// Fixed-lag smoothed poses (POSE_SMOOTHED; estimator.yaml fixed_lag.*). Without it the
  /// estimators smooth nothing.
  std::function<void(size_t vehicle, const PoseEstimate&)> pose_smoothed;
  std::function<void(size_t vehicle, const std::vector<AnchorEstimate>&)> anchors;
  std::function<void(size_t vehicle, const EstimatorStatus&)> estimator_status;
  std::function<void(const AnchorInit&)> anchor_init;
  std::function<void(const CalibStatus&)> calib_status;
  std::function<void(const MissionStatus&)> mission_status;
};

class Pipeline {
 public:
  /// One vehicle.
  Pipeline(const PipelineOptions& options, const SystemSetup& setup, PipelineSinks sinks = {});
  /// A fleet: `fleet_setup` is what the calibrator knows (every vehicle's tags and the shared
  /// anchors, `mergeFleetSetups`); throws std::invalid_argument for an empty list or a tag that is
  /// not in `fleet_setup`.
  Pipeline(const PipelineOptions& options, std::vector<Vehicle> vehicles, const SystemSetup& fleet_setup,
           PipelineSinks sinks = {});
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  /// One sensor sample (IMU, baro, range, flight state, height) or command, then every message it causes.
  void onInput(const estimator::EstimatorInput& in) { onInput(0, in); }
  /// The same for vehicle `vehicle` (out of range: std::out_of_range).
  void onInput(size_t vehicle, const estimator::EstimatorInput& in);

  /// The end of the streams: every estimator processes what waits for an IMU sample (flushHeld),
  /// takes a re-run still on its worker (finishRerun) and emits its last fixed-lag smoothed poses
  /// (flushSmoothed); then every message they cause is delivered.
  void finish();

  size_t vehicleCount() const { return vehicles_.size(); }
  const std::string& vehicleName(size_t v) const { return vehicles_.at(v).name; }
  /// The estimator of vehicle `v` (0: the only one of a single vehicle).
  estimator::EstimatorNode& estimator(size_t v = 0) { return *estimators_.at(v); }
  const estimator::EstimatorNode& estimator(size_t v = 0) const { return *estimators_.at(v); }
  /// Null when calibration is disabled.
  const calib::CalibratorNode* calibrator() const { return calibrator_.get(); }
  const mission::MissionNode* mission() const { return mission_.get(); }
  /// ANCHOR_INITs handed to the estimators so far, as the calibrator sent them (initial beliefs,
  /// for evaluation).
  const std::vector<AnchorInit>& anchorInits() const { return anchor_inits_; }
  /// The pipeline's own counters (a fleet's inter-vehicle ranges).
  const Diagnostics& diagnostics() const { return diag_; }

 private:
  /// A POSE_SMOOTHED (a type of its own in the queue: it goes elsewhere than a POSE).
  struct SmoothedPose {
    PoseEstimate pose;
  };
  using Message = std::variant<PoseEstimate, SmoothedPose, std::vector<AnchorEstimate>, EstimatorStatus, AnchorInit, CalibStatus,
                               CalibCommand, EstimatorCommand, MissionStatus>;
  struct Event {
    size_t vehicle = 0;  ///< whose estimator sent it (estimator outputs only)
    Message msg;
  };
  void drain();
  /// The log context of vehicle v's estimator calls (common/log_context.h): its name in a fleet,
  /// none for one vehicle.
  const std::string* vehicleLogName(size_t v) const;

  PipelineOptions options_;
  PipelineSinks sinks_;
  std::vector<Vehicle> vehicles_;
  SystemSetup fleet_setup_;  ///< what the calibrator knows
  std::vector<std::unique_ptr<estimator::EstimatorNode>> estimators_;
  std::unique_ptr<calib::CalibratorNode> calibrator_;
  std::unique_ptr<mission::MissionNode> mission_;
  std::deque<Event> queue_;
  std::vector<AnchorInit> anchor_inits_;
  Diagnostics diag_;
  /// What the calibrator hears from the vehicles and says to each (the mesh once, the anchor beliefs' CI).
  std::unique_ptr<FleetCalibratorFeed> feed_;
  /// A fleet's ranges between its vehicles' tags (null for one vehicle).
  std::unique_ptr<PeerRangeFeed> peers_;
  /// An inter-vehicle range to the vehicle that learns more from it.
  void routeInterVehicleRange(const RangeSample& r);
  std::vector<std::optional<Timestamp>> last_pose_to_calibrator_;  ///< per vehicle
  /// Per vehicle, the POSE instants the calibrator took whose smoothed twin has not come yet
  /// (calibrator_on_smoothed).
  std::vector<std::set<int64_t>> awaiting_smoothed_;
  bool t0_set_ = false;
};

}  // namespace meshnav::pipeline
