#pragma once
/// @file pipeline.h
/// @brief The whole system in one process (`meshnav run`, docs/architecture.md): the estimator, the
/// calibrator and the mission sequencer node classes wired as the processes are over LCM
/// (RANGE → estimator and calibrator, POSE/ANCHORS → calibrator and mission, CALIB_CMD,
/// ANCHOR_INIT, ESTIMATOR_CMD, CALIB_STATUS), but deterministic: every message a node emits is
/// queued and delivered in FIFO order after the node returns, exactly once, never re-entrantly.

#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <variant>
#include <vector>

#include "calibrator/calibrator_options.h"
#include "calibrator/node/calibrator_node.h"
#include "calibrator/node/calibrator_node_options.h"
#include "common/messages.h"
#include "common/setup.h"
#include "estimator/core/estimator_options.h"
#include "estimator/node/estimator_input.h"
#include "estimator/node/estimator_node.h"
#include "mission/mission.h"
#include "mission/mission_node.h"

namespace meshnav::pipeline {

struct PipelineOptions {
  estimator::EstimatorOptions estimator;
  calib::CalibratorOptions calibrator;
  calib::CalibratorNodeOptions calibrator_node;
  /// Mission steps; without one, new anchors are collected and calibrated automatically
  /// (calibrator_node.auto_mode is forced on).
  std::optional<mission::Mission> mission;
  bool calibration_enabled = true;     ///< false: no calibrator (known anchors only)
  double pose_to_calibrator_hz = 50.0; ///< POSE decimation towards the calibrator (0: every pose) [Hz]
};

/// What the pipeline emits (the channels a logger would record).
struct PipelineSinks {
  std::function<void(const PoseEstimate&)> pose;
  std::function<void(const std::vector<AnchorEstimate>&)> anchors;
  std::function<void(const EstimatorStatus&)> estimator_status;
  std::function<void(const AnchorInit&)> anchor_init;
  std::function<void(const CalibStatus&)> calib_status;
  std::function<void(const MissionStatus&)> mission_status;
};

class Pipeline {
 public:
  Pipeline(const PipelineOptions& options, const SystemSetup& setup, PipelineSinks sinks = {});
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  /// One sensor sample (IMU, baro, range, flight state, height) or command, then every message it causes.
  void onInput(const estimator::EstimatorInput& in);

  estimator::EstimatorNode& estimator() { return *estimator_; }
  const estimator::EstimatorNode& estimator() const { return *estimator_; }
  /// Null when calibration is disabled.
  const calib::CalibratorNode* calibrator() const { return calibrator_.get(); }
  const mission::MissionNode* mission() const { return mission_.get(); }
  /// ANCHOR_INITs handed to the estimator so far (initial beliefs, for evaluation).
  const std::vector<AnchorInit>& anchorInits() const { return anchor_inits_; }

 private:
  using Event = std::variant<PoseEstimate, std::vector<AnchorEstimate>, EstimatorStatus, AnchorInit, CalibStatus,
                             CalibCommand, EstimatorCommand, MissionStatus>;
  void drain();

  PipelineOptions options_;
  PipelineSinks sinks_;
  std::unique_ptr<estimator::EstimatorNode> estimator_;
  std::unique_ptr<calib::CalibratorNode> calibrator_;
  std::unique_ptr<mission::MissionNode> mission_;
  std::deque<Event> queue_;
  std::vector<AnchorInit> anchor_inits_;
  std::optional<Timestamp> last_pose_to_calibrator_;
  bool t0_set_ = false;
};

}  // namespace meshnav::pipeline
