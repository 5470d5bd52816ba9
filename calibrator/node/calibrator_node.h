#pragma once
/// @file calibrator_node.h
/// @brief The `calibrator` node (docs/channels.md, docs/calibration.md), free of LCM: consumes RANGE, POSE, ANCHORS and
/// CALIB_CMD through `onXxx()` and publishes ANCHOR_INIT and CALIB_STATUS through sink callbacks.
/// The same class runs behind LCM (calibrator/process/) and in the in-process pipeline.
///
/// **What is collected.** For every *unknown* anchor x (an anchor id not in
/// `setup.abs_anchor_positions`) that is collecting, every range between x and another device
/// D is kept, D being
///  - a tag of the setup (placed at p_TinG = p_IinG + R_ItoG·p_TinI from the pose history at the
///    range time, Σ_T = Σ_p + R[p_TinI]ₓΣ_θ[p_TinI]ₓᵀRᵀ, as in `ObservationBuilder`),
///  - a known anchor (setup position, σ from `abs_anchor_sigmas`),
///  - an anchor calibrated by this node (position and covariance from the estimator's ANCHORS when
///    it reports the anchor, else from the calibration), or
///  - another unknown anchor not calibrated yet: anchors are stationary, so such a range becomes
///    usable when D is calibrated (it then calibrates the pair bias γ_Dx the estimator needs for
///    anchor–anchor ranges). Until then it "waits for a reference".
/// Ranges involving no collecting anchor (tag–known anchor, tag–calibrated anchor, ...) are
/// counted as `ranges_not_needed` and dropped.
///
/// **Commands** (CALIB_CMD; an empty anchor list means "all"):
///  - Collect: (re)start collecting the listed anchors with an empty buffer; with an empty list,
///    every uncalibrated anchor and every anchor seen later. Naming a *calibrated* anchor forgets
///    its calibration (it stops being a reference): the way to re-calibrate a moved anchor after
///    ESTIMATOR_CMD RemoveInstance.
///  - Calibrate: calibrates the listed (in the listed order) or all collecting/refused anchors
///    (ascending id) now. Within one command an anchor calibrated first is a reference for the
///    next ones, so every pair of the batch gets a bias. Tag ranges are placed with the pose
///    history; ranges newer than the newest pose wait in the buffer for the next calibration;
///    older tag ranges without a pose (a gap in the history) are dropped (`ranges_dropped_no_pose`).
///    On success: ANCHOR_INIT (CalibrationResult::toAnchorInit, one PairBias per reference device),
///    state "calibrated", the anchor becomes a reference. On refusal: state "refused" with the
///    reason, and collecting goes on.
///  - Abort: stop collecting the listed (or all uncalibrated) anchors and drop their buffers; with
///    an empty list also anchors seen later are not collected until the next Collect.
///  - **Repeats.** A command is identified by (issue time `t`, action, anchor list). The mission
///    re-sends an unanswered command with its original `t` (mission_node.h, resends); a command
///    whose identity was already executed (among the last `kMaxCommandKeys`) is a no-op, counted
///    as "CALIB_CMD:duplicate". So a late answer never makes a re-sent Collect forget a
///    calibration or drop collected ranges, a re-sent Abort never stops a later Collect, and no
///    anchor is calibrated (ANCHOR_INIT) twice by one command. A new command (new `t`) still acts.
///
/// **Automatic mode** (CalibratorNodeOptions::auto_mode, used when no mission is given): criterion
/// in calibrator_node_options.h, checked every `auto_check_period_s` of data time.
///
/// **Time.** Data time is the newest time of any range or pose seen (commands do not advance it:
/// they may come from a wall clock). A range or pose (or a tick) stamped farther than
/// `time_max_offset` ahead of it (behind: `history_window` + `time_max_offset`) is refused and counted ("RANGE:time_ahead", "POSE:time_behind",
/// "tick:time_ahead", ...; common/time_guard.h), so it never moves the data time. Calibration results are stamped with the data time.
/// CALIB_STATUS is published whenever data time passes the next multiple of `status_period_s`
/// (driven by the inputs, or by `tick()` when no input flows), and right after every Calibrate
/// command. Counters (`CalibStatus::counters`, also `diagnostics()`): ranges_received,
/// ranges_kept, ranges_not_needed, ranges_not_collecting, ranges_evicted, ranges_dropped_no_pose,
/// ranges_waiting_for_pose, ranges_waiting_for_reference (at the last calibration attempt),
/// bad_range, unknown_device, bad_pose, pose_too_old, poses_out_of_order, bad_anchor_estimate,
/// bad_command, calibrations_ok, calibrations_refused.
///
/// **Duplicates**: a range with the time and ids of one already received (within
/// `time_max_offset` of data time) is dropped and counted ("RANGE:duplicate").
///
/// **Several vehicles** (`./meshnav run --fleet`, pipeline.h): the setup then holds the tags of every
/// vehicle and `vehicle_of_tag` says whose each is; POSE of vehicle v goes to `onPose(p, v)` and
/// fills v's own pose history, and a range of a tag is placed with its vehicle's history. Anchors
/// are shared, so one calibration uses the ranges of every vehicle's tags. A single vehicle is
/// vehicle 0 (the default).
///
/// **Bad input** (non-finite or absurd range, self-range, ids ≤ 0, tag-typed ids not in the setup,
/// the IMU/baro ids, non-finite poses or covariances, poses older than the history window) is
/// logged, counted and dropped; it never throws. Not thread-safe: call from one thread.

#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "calibrator/anchor_calibrator.h"
#include "calibrator/calibration_types.h"
#include "calibrator/calibrator_options.h"
#include "calibrator/node/calibrator_node_options.h"
#include "calibrator/observation_builder.h"
#include "common/diagnostics.h"
#include "common/messages.h"
#include "common/setup.h"
#include "common/time_guard.h"
#include "common/types.h"

namespace meshnav::calib {

/// Where the node's outputs go (unset sinks are skipped).
struct CalibratorSinks {
  std::function<void(const AnchorInit&)> anchor_init;  ///< ANCHOR_INIT
  std::function<void(const CalibStatus&)> status;      ///< CALIB_STATUS
};

class CalibratorNode {
 public:
  /// Throws std::invalid_argument for invalid node options.
  /// `vehicle_of_tag`: the vehicle index of each tag of `setup` (tags not listed: vehicle 0); throws
  /// std::invalid_argument when it names an id that is not a tag of the setup.
  CalibratorNode(const CalibratorOptions& options, const SystemSetup& setup, CalibratorSinks sinks = {},
                 const CalibratorNodeOptions& node_options = {}, std::map<SensorId, size_t> vehicle_of_tag = {});

  void onRange(const RangeSample& r);
  /// A pose of vehicle `vehicle` (0 for a single vehicle; an index no tag has is refused, "bad_pose").
  void onPose(const PoseEstimate& p, size_t vehicle = 0);
  /// The estimator's current anchor beliefs (ANCHORS); those of calibrated anchors become their
  /// reference positions and covariances.
  void onAnchors(const std::vector<AnchorEstimate>& anchors);
  void onCommand(const CalibCommand& c);
  /// Advances data time to `now` (ignored when older than the data time) and runs what is due:
  /// status heartbeat, automatic calibrations.
  void tick(Timestamp now);

  /// Status at the current data time (what the heartbeat publishes).
  CalibStatus status() const;
  /// Results of the calibration attempts so far (the last `kMaxResults`), in order, refused ones
  /// included (for `writeCalibrationYaml`); per-observation `inliers` flags are not kept.
  const std::vector<CalibrationResult>& results() const { return results_; }
  static constexpr size_t kMaxResults = 1000;
  /// Anchors calibrated by this node.
  std::vector<SensorId> calibratedAnchors() const;
  /// Newest data time seen (nullopt before any input).
  std::optional<Timestamp> dataTime() const { return newest_; }
  const Diagnostics& diagnostics() const { return diag_; }
  const CalibratorNodeOptions& nodeOptions() const { return node_options_; }
  const CalibratorOptions& options() const { return calibrator_.options(); }
  /// Poses held in the histories (every vehicle's).
  size_t poseHistorySize() const;
  /// Vehicles, i.e. pose histories (1 + the largest index in `vehicle_of_tag`).
  size_t vehicleCount() const { return histories_.size(); }
  /// Identities of executed commands kept to recognise a re-sent one.
  static constexpr size_t kMaxCommandKeys = 1024;

 private:
  enum class State { Idle, Collecting, Calibrated, Refused };
  static const char* toString(State s);

  /// One unknown anchor.
  struct Track {
    State state = State::Idle;
    std::deque<RangeSample> ranges;             ///< collected ranges (any order)
    std::map<SensorId, int64_t> ranges_by_device;  ///< other device → ranges in `ranges`
    std::string reason;                         ///< refusal reason
    std::optional<CalibrationResult> result;    ///< last successful calibration
    Timestamp next_auto_check;
  };

  /// Observations of x from its buffer; tag ranges in a pose gap are erased from the buffer.
  struct Built {
    std::vector<CalibObservation> obs;
    int64_t waiting_for_pose = 0;
    int64_t waiting_for_reference = 0;
    int64_t dropped_no_pose = 0;
  };
  Built buildObservations(SensorId x, Track& track);
  /// Position and covariance of a stationary reference (known or calibrated anchor).
  std::optional<std::pair<Eigen::Vector3d, Eigen::Matrix3d>> anchorReference(SensorId id) const;
  std::optional<std::pair<Eigen::Vector3d, Eigen::Matrix3d>> tagPosition(SensorId tag, Timestamp t) const;
  /// The pose history of the vehicle that carries `tag`.
  const std::vector<PoseEstimate>& historyOf(SensorId tag) const;
  bool isReference(SensorId id) const;
  bool isUnknownAnchor(SensorId id, UwbType type) const;

  /// Calibrates x from `built`, with `options` instead of the calibrator's own when given.
  void calibrateAnchor(SensorId x, Track& track, Built built, bool automatic,
                       const CalibratorOptions* options = nullptr);
  void startCollecting(SensorId x, Track& track);
  void stopCollecting(Track& track);
  void addRange(SensorId x, Track& track, const RangeSample& r);
  Track& track(SensorId x);
  void advance(Timestamp t);
  /// The time guard on an input of `kind` at `t`; false: refused and counted.
  bool admitTime(const std::string& kind, Timestamp t);
  void runPeriodic();
  void checkAuto(SensorId x, Track& track);
  void keepResult(CalibrationResult res);
  void pruneOldTagRanges();
  void publishStatus();
  /// True (counted, logged) when a command with the identity of `c` was executed before; else
  /// remembers it.
  bool isRepeat(const CalibCommand& c);

  CalibratorNodeOptions node_options_;
  SystemSetup setup_;
  CalibratorSinks sinks_;
  AnchorCalibrator calibrator_;
  ObservationBuilder prior_source_;  ///< only for the a-priori pair biases of setup.yaml
  Diagnostics diag_;

  std::map<SensorId, size_t> vehicle_of_tag_;
  std::vector<std::vector<PoseEstimate>> histories_;  ///< per vehicle: sorted by time, within the history window
  std::map<SensorId, AnchorEstimate> beliefs_;
  std::map<SensorId, Track> tracks_;
  std::set<std::tuple<int64_t, SensorId, SensorId>> seen_ranges_;  ///< (µs, ids) within time_max_offset
  using CommandKey = std::tuple<int64_t, int, std::vector<SensorId>>;  ///< (t µs, action, anchors)
  std::set<CommandKey> seen_commands_;     ///< executed commands (at most kMaxCommandKeys) ...
  std::deque<CommandKey> command_order_;   ///< ... oldest first, for eviction
  bool collect_new_anchors_ = true;
  std::vector<CalibrationResult> results_;
  std::optional<Timestamp> newest_;
  TimeGuard time_guard_;
  std::optional<Timestamp> next_status_;
  std::optional<Timestamp> next_prune_;
  int64_t last_waiting_for_pose_ = 0;       ///< at the last calibration attempt
  int64_t last_waiting_for_reference_ = 0;  ///< at the last calibration attempt
};

}  // namespace meshnav::calib
