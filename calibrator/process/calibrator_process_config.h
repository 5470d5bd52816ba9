#pragma once
/// @file calibrator_process_config.h
/// @brief What the `calibrator` process reads from its command line and `--config` file, free of
/// LCM so that it is unit-tested (tests/integration/process_config_test.cpp): the option list, the
/// loading of `config/calibrator.yaml` (`calibrator:` + `calibrator_node:` maps), `--auto`, the
/// range σ_d taken from setup.yaml, and the calibration results file written during the run.

#include <cstdint>
#include <string>
#include <vector>

#include "calibrator/calibration_types.h"
#include "calibrator/calibrator_options.h"
#include "calibrator/node/calibrator_node_options.h"
#include "common/cli.h"
#include "common/setup.h"

namespace meshnav::calib {

/// Options of the `calibrator` process.
struct CalibratorProcessConfig {
  std::string setup_path;           ///< --setup (required to run, unless --fleet)
  /// --fleet: serve every vehicle of this fleet file (pipeline/fleet.h) over LCM, each on its own
  /// prefix and bus (docs/fleet.md, "The fleet's calibrator over LCM"); excludes --setup and
  /// --channel-prefix
  std::string fleet_path;
  std::string bus = "per-vehicle";  ///< --bus with --fleet: per-vehicle | shared (transport/fleet_bus.h)
  std::string config_path;          ///< --config ("" = built-in defaults)
  std::string out_yaml;             ///< --out-yaml ("" = none)
  std::string state_dir;            ///< --state-dir: input journal of a restart ("" = none)
  double pose_rate_hz = 50.0;       ///< --pose-rate: POSE decimation towards the node (0 = every pose) [Hz]
  double heartbeat_s = 1.0;         ///< --heartbeat: wall time between CALIB_STATUS heartbeats [s]
  /// --smoothed-poses: each POSE the node took is replaced by its POSE_SMOOTHED twin when that
  /// comes (the estimator's fixed-lag smoother; issue 35 item 3, docs/smoother.md)
  bool smoothed_poses = false;
  bool print_config = false;        ///< --print-config
  bool auto_requested = false;      ///< --auto (forces node.auto_mode on after --config is read)
  CalibratorOptions calibrator;     ///< `calibrator:` of --config
  CalibratorNodeOptions node;       ///< `calibrator_node:` of --config, auto_mode forced on by --auto
  /// Whether --config sets `calibrator.sigma_range`; if not, applySetup() takes setup.yaml's.
  bool sigma_range_from_config = false;
  std::string sigma_range_source = "built-in default";  ///< for the log

  /// Multi-line listing (YAML-like, both option maps and the process options).
  std::string toString() const;
};

/// What the process does (the first paragraph of --help).
extern const char* const kCalibratorProcessDescription;

/// Declares the process's own options on `cli`, bound to the fields of `config` (their initial
/// values are the defaults --help shows); values out of range are refused by the parse. The
/// options every process has (--lcm-url, --log-level) come from transport::ProcessMain.
void declareCalibratorProcessOptions(Cli& cli, CalibratorProcessConfig& config);

/// After the parse: loads --config and applies --auto. Throws std::runtime_error naming the file
/// and key on a bad file.
void loadCalibratorProcessConfig(CalibratorProcessConfig& config);

/// σ_d from `setup.noise.sigma_range` unless the config file set it.
void applySetup(CalibratorProcessConfig& config, const SystemSetup& setup);

/// Writes the calibration results YAML (calibration_io.h) when the number of calibration attempts
/// changed since the last write; the file is replaced atomically (written beside, then renamed), so
/// a reader never sees half a file.
class CalibrationYamlWriter {
 public:
  explicit CalibrationYamlWriter(std::string path) : path_(std::move(path)) {}
  bool enabled() const { return !path_.empty(); }
  const std::string& path() const { return path_; }
  /// `attempts` = calibrations done so far (ok + refused). Writes when it changed, or when
  /// `force` (on exit). Returns true when written; I/O errors are logged and return false.
  bool update(const std::vector<CalibrationResult>& results, int64_t attempts, bool force = false);

 private:
  std::string path_;
  int64_t written_attempts_ = -1;
};

}  // namespace meshnav::calib
