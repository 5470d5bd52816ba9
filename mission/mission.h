#pragma once
/// @file mission.h
/// @brief A mission script (docs/formats.md, mission file): timed steps that drive the calibrator and the estimator.
/// @code
/// # times are the dataset's seconds relative to its first sample
/// collect_at_start: true        # optional (default true): a Collect for all anchors at the first sample
/// steps:
///   - {t: 80.0,  action: calibrate, anchors: [106, 107]}
///   - {t: 100.0, action: calibrate, anchors: [108, 109, 110]}
/// @endcode
/// Actions: `collect` (CALIB_CMD Collect: start/restart collecting), `calibrate` (CALIB_CMD
/// Calibrate), `abort` (CALIB_CMD Abort) — `anchors` optional, missing or empty = all — and
/// `remove` (one ESTIMATOR_CMD RemoveInstance per listed id; `anchors` required).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/types.h"
#include "mission/flight_plan.h"

namespace meshnav::mission {

enum class MissionAction { Collect, Calibrate, Remove, Abort };

/// "collect", "calibrate", "remove", "abort".
const char* toString(MissionAction a);

struct MissionStep {
  double t_s = 0.0;                 ///< time after the first sample [s] (>= 0)
  MissionAction action = MissionAction::Calibrate;
  std::vector<SensorId> anchors;    ///< empty: all (not allowed for remove)
  int line = 0;                     ///< line in the mission file (1-based; 0: built in code)
  /// "t=80.0 s calibrate 106,107".
  std::string describe() const;
};

struct Mission {
  std::string source;               ///< file it came from (for messages)
  bool collect_at_start = true;     ///< CALIB_CMD Collect (all) at the first sample
  std::vector<MissionStep> steps;   ///< sorted by t (stable: equal times keep file order)
  /// The flight a closed loop flies (key `flight`, flight_plan.h); nullopt for a replayed dataset.
  std::optional<FlightPlan> flight;
};

/// Loads a mission file. Throws std::runtime_error naming the file, the line and the key
/// (e.g. "m.yaml:4: key 'steps[1].action': unknown action 'calbrate' (collect|calibrate|remove|abort)").
Mission loadMission(const std::string& path);
/// Parses mission YAML text; `source` names it in messages.
Mission parseMission(const std::string& yaml_text, const std::string& source);

}  // namespace meshnav::mission
