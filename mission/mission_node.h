#pragma once
/// @file mission_node.h
/// @brief The `mission` node (docs/channels.md), free of LCM: runs a `Mission` in data time.
/// Subscribes POSE (or any data time, `onTime`), CALIB_STATUS and ESTIMATOR_STATUS; publishes
/// CALIB_CMD, ESTIMATOR_CMD and MISSION_STATUS through sinks. The same class runs behind LCM
/// (mission/process/) and in the in-process pipeline.
///
/// - **t0.** Step times are seconds after t0, the dataset's first sample. `setT0()` sets it (the
///   pipeline knows the first sample; a process replaying a simulated dataset can pass 0);
///   otherwise the first `onTime`/`onPose` defines it. Note that over LCM the first POSE comes
///   only after the estimator initialised, so taking t0 from it shifts the mission by that delay.
/// - **Start.** At the first data time, when `Mission::collect_at_start`, one CALIB_CMD Collect
///   with an empty list (= all anchors, also those seen later).
/// - **Steps** run once each, in order, at the first data time >= t0 + step.t (several steps passed
///   by one jump all run, in order). Commands carry the data time at which they are issued.
///   collect/calibrate/abort → one CALIB_CMD; remove → one ESTIMATOR_CMD RemoveInstance per id.
///   Data time going backwards never re-runs a step (counted as "time_backwards").
/// - **Clock rebased** (`onClockRebased`: the data clock followed a jump of the whole stream that
///   its TimeGuard agreed on). When the first data time was the only one accepted and t0 was taken
///   from it, that time was the bad one (a sender's wrong first stamp): the mission starts again
///   at the new time, t0 with it, and what it issued at the wrong time is issued again
///   ("t0_retaken"). Otherwise (a --t0 of the user's, or a real stream that paused after many
///   times) t0 stays, no step runs twice and the node follows the new time line ("clock_rebased").
/// - **Resends** (a lossy link, docs/deployment.md): a CALIB_CMD counts as answered once a
///   CALIB_STATUS shows its effect — Collect: its anchors (all: every listed one) no longer `idle`;
///   Calibrate: its anchors `calibrated` or `refused` (all: none `collecting`); Abort: none of its
///   anchors `collecting`. Until then it is sent again (the same message, with its original issue
///   time) every `resend_period_s` of data time, at most `max_resends` times ("calib_cmd_resent").
///   A late CALIB_STATUS (a loaded calibrator: at 10x replay 1 s of data time is 0.1 s of wall
///   time) thus also causes resends; the calibrator executes a command (issue time, action,
///   anchors) once and ignores its repeats ("CALIB_CMD:duplicate", calibrator_node.h).
///   The answer to a Collect or Abort comes with the calibrator's periodic CALIB_STATUS (1 s of
///   data time): a resend period not above that races it (the mission process uses 2 s).
/// - **Status** (MISSION_STATUS, the heartbeat) every `status_period_s` of data time and right
///   after a step ran: index of the last executed step, step count and a text with the next step
///   and the calibrator's per-anchor states from CALIB_STATUS (refusals are also logged).
/// Not thread-safe: call from one thread.

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "common/messages.h"
#include "common/types.h"
#include "mission/mission.h"

namespace meshnav::mission {

struct MissionSinks {
  std::function<void(const CalibCommand&)> calib_cmd;          ///< CALIB_CMD
  std::function<void(const EstimatorCommand&)> estimator_cmd;  ///< ESTIMATOR_CMD
  std::function<void(const MissionStatus&)> status;            ///< MISSION_STATUS
};

struct MissionNodeOptions {
  double status_period_s = 1.0;  ///< MISSION_STATUS period in data time [s] (> 0)
  double resend_period_s = 0.0;  ///< unanswered CALIB_CMD sent again after this data time [s] (0 = never; the
                                 ///< mission process: --resend-period, 2 s)
  int max_resends = 30;          ///< ... at most this many times each [-]
};

class MissionNode {
 public:
  /// Throws std::invalid_argument for a non-positive status period.
  MissionNode(Mission mission, MissionSinks sinks = {}, MissionNodeOptions options = {});

  /// Sets t0 (the dataset's first sample). Ignored with a warning once the mission started.
  void setT0(Timestamp t0);
  void onPose(const PoseEstimate& p) { onTime(p.t); }
  /// Advances data time; runs the start, the due steps and the heartbeat.
  void onTime(Timestamp data_time);
  /// The data clock jumped to `data_time` by agreement of its inputs (see the file comment), then
  /// as onTime.
  void onClockRebased(Timestamp data_time);
  void onCalibStatus(const CalibStatus& s);
  void onEstimatorStatus(const EstimatorStatus& s);

  MissionStatus status() const;
  bool started() const { return started_; }
  /// Every step ran.
  bool finished() const { return started_ && next_step_ >= mission_.steps.size(); }
  /// Index of the next step to run (== number of steps run).
  size_t nextStep() const { return next_step_; }
  std::optional<Timestamp> t0() const { return t0_; }
  const Mission& mission() const { return mission_; }
  const Diagnostics& diagnostics() const { return diag_; }

 private:
  void runStep(const MissionStep& step);
  void sendCalib(const CalibCommand& c);
  /// Whether the last CALIB_STATUS shows the effect of `c`.
  bool answered(const CalibCommand& c) const;
  void resendUnanswered();
  void publishStatus();
  std::string text() const;

  Mission mission_;
  MissionSinks sinks_;
  MissionNodeOptions options_;
  Diagnostics diag_;
  std::optional<Timestamp> t0_;
  bool t0_from_data_ = false;  ///< t0 was the first data time (no setT0)
  int64_t times_accepted_ = 0;  ///< data times accepted since the start (the start's included)
  Timestamp now_;
  bool started_ = false;
  size_t next_step_ = 0;
  std::optional<Timestamp> next_status_;
  std::map<SensorId, CalibAnchorStatus> calib_;  ///< last CALIB_STATUS per anchor
  bool estimator_initialized_ = false;
  struct Sent {
    CalibCommand cmd;
    Timestamp last;
    int resends = 0;
  };
  std::vector<Sent> unanswered_;  ///< CALIB_CMDs whose effect no CALIB_STATUS has shown yet
};

}  // namespace meshnav::mission
