#pragma once
/// @file run_recorder.h
/// @brief The recorder behind the `logging` process (LCM-free): writes what the estimator and the
/// calibrator publish into the files of docs/formats.md and keeps a summary of the run.
///
/// Files in the output folder:
///  - estimate.csv    every POSE (common/estimate_io.h)
///  - estimate_smoothed.csv  every POSE_SMOOTHED (the same columns), from the first one on
///  - anchors.csv     every anchor of every ANCHORS message
///  - anchor_init.yaml  every ANCHOR_INIT, in the calibration YAML format (`anchors:` list),
///                    rewritten at each one (into a temporary file renamed over it: a kill -9
///                    loses none and never leaves it half written)
///  - groundtruth.csv GROUND_TRUTH when present (TUM)
///  - summary.yaml    written by finish(): messages and bytes per channel, the last
///                    ESTIMATOR_STATUS / CALIB_STATUS / MISSION_STATUS, and the recorder's counters

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "common/estimate_io.h"
#include "common/messages.h"
#include "common/types.h"

namespace meshnav::logging {

/// Traffic of one channel.
struct ChannelStats {
  int64_t messages = 0;
  int64_t bytes = 0;
  int64_t first_wall_utime = 0;  ///< receipt time of the first message [µs, Unix epoch]
  int64_t last_wall_utime = 0;   ///< receipt time of the last message [µs, Unix epoch]
};

class RunRecorder {
 public:
  /// Creates `out_dir` and opens estimate.csv and anchors.csv there (header written at once).
  /// `append` (a logger restarted within the same run): the files are continued, and the
  /// ANCHOR_INITs of anchor_init.yaml are taken back. A row the killed logger left half written at
  /// the end of a CSV is cut off first (logging/torn_tail.h) and counted as
  /// "<file>:torn_row_cut" in diagnostics(). Throws std::runtime_error when the folder or files
  /// cannot be written.
  explicit RunRecorder(const std::string& out_dir, bool append = false);
  ~RunRecorder();

  /// Any message on any channel (for the summary), received at `wall_utime`.
  void countMessage(const std::string& channel, int64_t bytes, int64_t wall_utime);

  void onPose(const PoseEstimate& e);
  /// A fixed-lag smoothed pose: estimate_smoothed.csv is opened at the first one (continued when
  /// `append`, its torn last row cut).
  void onPoseSmoothed(const PoseEstimate& e);
  void onAnchors(const std::vector<AnchorEstimate>& anchors);
  void onAnchorInit(const AnchorInit& a);
  void onGroundTruth(const PoseSample& p);
  void onEstimatorStatus(const EstimatorStatus& s) { last_estimator_status_ = s; }
  void onCalibStatus(const CalibStatus& s) { last_calib_status_ = s; }
  void onMissionStatus(const MissionStatus& s) { last_mission_status_ = s; }

  /// Flushes the CSV files (call periodically, so readers see progress).
  void flush();
  /// Flushes everything and writes anchor_init.yaml, groundtruth.csv and summary.yaml (with the
  /// process's own counters `process_diag` and the recorder's diagnostics()). Idempotent.
  void finish(const Diagnostics& process_diag);

  /// Multi-line human-readable summary (what finish() also logs).
  std::string summaryText() const;

  const std::map<std::string, ChannelStats>& channels() const { return channels_; }
  int64_t posesWritten() const { return n_poses_; }
  int64_t smoothedPosesWritten() const { return n_smoothed_; }
  int64_t anchorRowsWritten() const { return n_anchor_rows_; }
  const std::string& outDir() const { return out_dir_; }
  /// The recorder's own counters (torn rows cut on a restart).
  const Diagnostics& diagnostics() const { return diag_; }

 private:
  std::string out_dir_;
  std::unique_ptr<EstimateCsvWriter> estimate_;
  std::unique_ptr<EstimateCsvWriter> smoothed_;  ///< at the first POSE_SMOOTHED
  bool append_ = false;
  std::unique_ptr<AnchorsCsvWriter> anchors_;
  std::vector<AnchorInit> anchor_inits_;
  std::vector<PoseSample> ground_truth_;
  std::map<std::string, ChannelStats> channels_;
  std::optional<EstimatorStatus> last_estimator_status_;
  std::optional<CalibStatus> last_calib_status_;
  std::optional<MissionStatus> last_mission_status_;
  int64_t n_poses_ = 0;
  int64_t n_smoothed_ = 0;
  int64_t n_anchor_rows_ = 0;
  bool finished_ = false;
  Diagnostics diag_;
};

}  // namespace meshnav::logging
