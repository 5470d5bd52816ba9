#pragma once
/// @file calibrator_node_options.h
/// @brief Run-time behaviour of the `CalibratorNode` (what to collect, memory bounds, status rate,
/// automatic mode). The calibration maths is tuned by `CalibratorOptions` (calibrator_options.h).
///
/// YAML layout (every key optional; unknown keys are an error naming the file and the key):
/// @code
/// calibrator_node:
///   auto_mode: false              # calibrate by itself (used when no mission is given)
///   auto_min_ranges: 300          # usable ranges to the anchor [-]
///   auto_min_references: 2        # reference devices with >= min_measurements_per_reference ranges [-]
///   auto_min_plane_spread: 0.5    # RMS of tag positions off their best plane [m]
///   auto_min_line_spread: 0.5     # RMS of tag positions off their best line [m]
///   auto_check_period: 1.0        # how often the criterion is evaluated (data time) [s]
///   auto_retry_period: 10.0       # wait after an automatic calibration was refused [s]
///   retry_refused: true           # also without auto_mode: retry a refused anchor by the criterion
///   collect_from_start: true      # collect every unknown anchor from its first range
///   history_window: 300.0         # pose history and tag ranges kept [s]
///   max_ranges_per_anchor: 20000  # the oldest range is evicted beyond this [-]
///   status_period: 1.0            # CALIB_STATUS period (data time) [s]
///   time_max_offset: 10.0         # RANGE/POSE stamped farther from the data time: refused [s]
///   time_rebase_after: 50         # agreeing refused inputs in a row that move the clock [-]
/// @endcode
///
/// **Automatic criterion** (auto_mode): an anchor that is collecting (or was refused more than
/// `auto_retry_period` ago) is calibrated as soon as, at a check,
///  1. at least `auto_min_ranges` of its ranges have a reference position now (tag pose
///     available in the history, known anchor, or calibrated anchor),
///  2. at least `auto_min_references` reference devices have `min_measurements_per_reference`
///     of them, and
///  3. the library's refusal checks (`checkReferenceGeometry`) pass with the stricter spreads
///     `auto_min_plane_spread` / `auto_min_line_spread`: the tag positions span a volume, not
///     just the plane of a hover or the line of a take-off.
///
/// **Retry of refused anchors** (`retry_refused`, also when a mission drives the calibrator): an
/// anchor refused by a Calibrate command keeps collecting and is tried again by the same criterion
/// once `auto_retry_period` has passed and new data makes it pass (a calibration refused for too
/// few or too coplanar data is not final).

#include <string>

#include "common/time_guard.h"

namespace YAML { class Node; }

namespace meshnav::calib {

struct CalibratorNodeOptions {
  // --- automatic mode ---------------------------------------------------------------------
  bool auto_mode = false;
  int auto_min_ranges = 300;
  int auto_min_references = 2;
  double auto_min_plane_spread_m = 0.5;
  double auto_min_line_spread_m = 0.5;
  double auto_check_period_s = 1.0;
  double auto_retry_period_s = 10.0;
  bool retry_refused = true;  ///< retry refused anchors by the automatic criterion, also without auto_mode

  // --- collection and memory --------------------------------------------------------------
  bool collect_from_start = true;   ///< false: an anchor is collected only after a Collect naming it (or all)
  double history_window_s = 300.0;  ///< poses older than newest − window are dropped, so are tag ranges [s]
  int max_ranges_per_anchor = 20000;

  // --- output ------------------------------------------------------------------------------
  double status_period_s = 1.0;     ///< CALIB_STATUS heartbeat period in data time [s]

  // --- time guard (common/time_guard.h) ------------------------------------------------------
  TimeGuardOptions time;            ///< keys time_max_offset [s], time_rebase_after [-]

  /// Reads the keys present under `node` (the `calibrator_node:` map). Throws std::runtime_error
  /// naming `where` and the key on an unknown key or a bad value.
  static CalibratorNodeOptions fromYaml(const YAML::Node& node, const std::string& where);
  /// Throws std::invalid_argument naming the first invalid option.
  void validate() const;
  /// Multi-line "key: value" listing.
  std::string toString() const;
};

}  // namespace meshnav::calib
