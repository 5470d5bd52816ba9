#pragma once
/// @file calibrator_config.h
/// @brief The calibrator's configuration file (config/calibrator.yaml): a `calibrator:` map
/// (CalibratorOptions) and a `calibrator_node:` map (CalibratorNodeOptions); another top-level key
/// is an error so that a typo does not silently leave defaults. A file with neither map is read as
/// a flat `calibrator:` map. The one loader of the file (the calibrator process, `meshnav_run`,
/// `meshnav_calibrate`), following the rule of common/yaml_options.h.

#include <string>

#include "calibrator/calibrator_options.h"
#include "calibrator/node/calibrator_node_options.h"
#include "common/setup.h"

namespace meshnav::calib {

struct CalibratorConfig {
  CalibratorOptions calibrator;
  CalibratorNodeOptions node;
  /// Whether the file set `calibrator.sigma_range`; if not, applySetup() takes setup.yaml's.
  bool sigma_range_from_config = false;
  std::string sigma_range_source = "built-in default";  ///< for the log

  /// Loads `path` ("" = built-in defaults). Throws std::runtime_error naming the file and key.
  static CalibratorConfig load(const std::string& path);
  /// σ_d from `setup.noise.sigma_range` unless the config file set it (a value ≤ 0 is ignored with
  /// a warning).
  void applySetup(const SystemSetup& setup);
};

}  // namespace meshnav::calib
