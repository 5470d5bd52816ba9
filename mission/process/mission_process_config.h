#pragma once
/// @file mission_process_config.h
/// @brief The `mission` process's options and its small bits of logic, free of LCM so that they
/// are unit-tested (tests/integration/process_config_test.cpp):
///  - MissionProcessConfig: command line → options (`--t0 S|auto`, `--time-from CHANNELS`, ...);
///  - DataClock: data time over LCM comes from several channels (RANGE, POSE, ...) that do not
///    arrive in time order with respect to each other (POSE lags RANGE by the estimator's
///    processing); only advancing times are passed on to the MissionNode;
///  - MissionCompletion: when a finished mission may let the process exit (its last Calibrate
///    command answered by the calibrator, or a wall-clock linger passed).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/messages.h"
#include "common/diagnostics.h"
#include "common/time.h"
#include "common/time_guard.h"
#include "mission/mission.h"

namespace meshnav::mission {

/// Data channels whose message time may drive the mission clock (POSE always does).
inline const std::vector<std::string> kTimeChannels = {"RANGE", "IMU", "BARO", "FLIGHT_STATE"};

struct MissionProcessConfig {
  std::string mission_path;                     ///< --mission (required)
  std::optional<double> t0_s;                   ///< --t0: dataset time of step time 0 [s]; nullopt (auto): first data time
  std::vector<std::string> time_channels = {"RANGE"};  ///< --time-from: channels besides POSE that advance data time
  bool stay = false;                            ///< --stay: keep running after the mission finished
  double linger_s = 10.0;                       ///< --linger: wall time to wait for the calibrator's answer to the last step [s]
  double heartbeat_s = 1.0;                     ///< --heartbeat: wall time between MISSION_STATUS heartbeats [s]
  double status_period_s = 1.0;                 ///< --status-period: MISSION_STATUS period in data time [s]
  double resend_period_s = 2.0;                 ///< --resend-period: unanswered CALIB_CMD sent again [s] data time
                                               ///< (> the calibrator's 1 s CALIB_STATUS period, which may carry the answer)
  /// --fleet: the fleet's mission (docs/fleet.md): it follows the first vehicle of this fleet file
  /// (its POSE, RANGE, ESTIMATOR_STATUS, on its prefix and bus) and sends ESTIMATOR_CMD to every
  /// vehicle on its own prefix and bus (--bus); excludes --channel-prefix
  std::string fleet_path;
  std::string bus = "per-vehicle";              ///< --bus with --fleet: per-vehicle | shared (transport/fleet_bus.h)
  bool print_config = false;                    ///< --print-config
  std::string t0_text = "auto";                 ///< --t0 as given (S or auto), read by finishMissionProcessConfig
  std::string time_from_text = "RANGE";         ///< --time-from as given, read by finishMissionProcessConfig
  std::string toString() const;
};

/// What the process does (the first paragraph of --help).
extern const char* const kMissionProcessDescription;

/// Declares the process's own options on `cli`, bound to the fields of `config` (their initial
/// values are the defaults --help shows); numbers out of range are refused by the parse. The
/// options every process has (--lcm-url, --log-level) come from transport::ProcessMain.
void declareMissionProcessOptions(Cli& cli, MissionProcessConfig& config);

/// After the parse: reads --t0 (S or auto) and --time-from (channel list). Throws
/// std::runtime_error naming the option on a bad value.
void finishMissionProcessConfig(MissionProcessConfig& config);

/// Passes on only plausible, advancing data times (several channels, arriving out of order
/// between them). A time more than 10 s ahead of the current one is refused by a TimeGuard
/// (common/time_guard.h; a whole-stream jump is followed after 50 agreeing inputs) and counted as
/// DATA_TIME:time_ahead: one message stamped far ahead would otherwise fire every remaining step at
/// once and leave every real time "not newer" afterwards. Older times are harmless (a POSE lagging
/// the ranges): only beyond 600 s are they counted (DATA_TIME:time_behind). A followed jump back
/// (a replay started again) is reported as DATA_TIME:jumped_back; `rebased()` tells the caller,
/// which hands the jump to MissionNode::onClockRebased: steps already run are not run again, and a
/// mission whose t0 came from a wrong first stamp starts again at the new time. A wrong first stamp
/// less than 600 s ahead is not told apart from POSE lagging the ranges: it delays the mission by
/// its error (the process's --t0 avoids it).
class DataClock {
 public:
  DataClock() : guard_(TimeGuardOptions{10.0, 50, 600.0}) {}
  /// True when `t` is the new data time: admitted by the guard and newer than the last one (or the
  /// first after a jump the guard followed).
  bool advance(Timestamp t, Diagnostics& diag) {
    const TimeGuard::Verdict v = guard_.admit("DATA_TIME", t, diag);
    if (v == TimeGuard::Verdict::Ahead || v == TimeGuard::Verdict::Behind) return false;
    if (now_ && t <= *now_ && v != TimeGuard::Verdict::Rebased) return false;
    if (v == TimeGuard::Verdict::Rebased && now_ && t < *now_)
      diag.report("DATA_TIME:jumped_back", "mission: data time jumped back from t=" + formatSeconds(*now_) +
                                               " s to t=" + formatSeconds(t) +
                                               " s; steps already run are not run again");
    now_ = t;
    rebased_ = v == TimeGuard::Verdict::Rebased;
    return true;
  }
  std::optional<Timestamp> now() const { return now_; }
  /// The last advance() that returned true followed a jump of the whole stream (TimeGuard rebase).
  bool rebased() const { return rebased_; }

 private:
  TimeGuard guard_;
  std::optional<Timestamp> now_;
  bool rebased_ = false;
};

/// Decides when the process of a finished mission may exit. When the mission's last step is a
/// Calibrate, the process waits until a CALIB_STATUS received after the mission finished shows the
/// calibrator answered it: its attempt count (counters calibrations_ok + calibrations_refused) grew
/// past the count known when the mission finished, and none of the step's anchors (all anchors
/// for an empty list) is still "collecting". Otherwise, or after `linger_s` of wall time, it may
/// exit right away.
class MissionCompletion {
 public:
  MissionCompletion(const Mission& mission, double linger_s);
  /// Every CALIB_STATUS (before and after the mission finished).
  void onCalibStatus(const CalibStatus& s);
  /// The mission node reported finished() at wall time `wall_us` (first call counts).
  void onFinished(int64_t wall_us);
  bool finished() const { return finished_wall_us_.has_value(); }
  /// The calibrator answered the last step (or there is nothing to wait for).
  bool answered() const { return answered_; }
  /// May exit now: finished and (answered or lingered `linger_s`).
  bool done(int64_t wall_us) const;
  /// The linger ran out without an answer (for a warning).
  bool timedOut(int64_t wall_us) const;

 private:
  static int64_t attempts(const CalibStatus& s);
  std::optional<MissionStep> last_calibrate_;  ///< the last step, when it is a Calibrate
  double linger_s_;
  int64_t attempts_seen_ = 0;                  ///< in the newest CALIB_STATUS
  std::optional<int64_t> attempts_at_finish_;
  std::optional<int64_t> finished_wall_us_;
  bool answered_ = false;
};

}  // namespace meshnav::mission
