#include "calibrator/process/calibrator_process_config.h"

#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "calibrator/calibration_io.h"
#include "calibrator/node/calibrator_config.h"

namespace meshnav::calib {

const char* const kCalibratorProcessDescription =
    "Calibrates new UWB anchors fly-by (docs/calibration.md): subscribes RANGE, POSE, ANCHORS, CALIB_CMD; "
    "publishes ANCHOR_INIT (position, covariance, pair biases) and CALIB_STATUS (per-anchor state, counters; also "
    "a wall-clock heartbeat). Driven by a mission (CALIB_CMD) or, with --auto, by itself. Malformed messages are "
    "counted per channel and reported in CALIB_STATUS.";

void declareCalibratorProcessOptions(Cli& cli, CalibratorProcessConfig& c) {
  CLI::Option* setup = cli.optional("setup", c.setup_path,
                                     "system setup (setup.yaml: tags, known anchors, pair biases, noise); required "
                                     "unless --fleet")
                            ->type_name("FILE");
  cli.fleetServing(c.fleet_path, c.bus,
                   "serve a fleet (fleet.yaml: each vehicle's dataset and setup): every vehicle's P/RANGE, P/POSE, "
                   "P/ANCHORS in, its own P/ANCHOR_INIT out, each on its bus (--bus); CALIB_CMD and CALIB_STATUS on "
                   "the first vehicle's bus, where the fleet's mission runs (docs/fleet.md)")
      ->excludes(setup);
  cli.optional("config", c.config_path,
               "calibrator options YAML, `calibrator:` and `calibrator_node:` maps (default: built-in = "
               "config/calibrator.yaml); without calibrator.sigma_range, sigma_d is setup.yaml's "
               "noise.sigma_range, else the built-in one")
      ->type_name("FILE");
  cli.flag("auto", c.auto_requested,
           "calibrate automatically once an anchor's data suffices (when no mission drives the calibrator; sets "
           "calibrator_node.auto_mode)");
  cli.optional("state-dir", c.state_dir,
               "folder of the input journal (calibrator_inputs.lcmlog): every RANGE, decimated POSE, ANCHORS and "
               "CALIB_CMD the node consumed and every ANCHOR_INIT it sent, flushed at once; a restarted calibrator "
               "replays it first and so keeps what it had collected and calibrated, and sends an ANCHOR_INIT the "
               "stop kept from going out (docs/faults.md)")
      ->type_name("DIR");
  cli.optional("out-yaml", c.out_yaml,
               "write the calibration results YAML (calibrator/calibration_io.h) after every calibration and on exit")
      ->type_name("FILE");
  cli.option("pose-rate", c.pose_rate_hz, "POSE decimation towards the calibrator [Hz] (0 = every pose)")
      ->type_name("HZ")
      ->check(cli::nonNegative());
  cli.flag("smoothed-poses", c.smoothed_poses,
           "replace each POSE taken by its POSE_SMOOTHED twin when that comes (the estimator's fixed-lag smoother, "
           "fixed_lag.lag_s later; as meshnav_run --calibrate-on-smoothed)");
  cli.option("heartbeat", c.heartbeat_s, "wall seconds between heartbeat CALIB_STATUS")
      ->type_name("S")
      ->check(cli::positive());
  cli.flag("print-config", c.print_config, "print the options and exit");
}

void loadCalibratorProcessConfig(CalibratorProcessConfig& c) {
  if (!c.config_path.empty()) {
    const CalibratorConfig cc = CalibratorConfig::load(c.config_path);
    c.calibrator = cc.calibrator;
    c.node = cc.node;
    c.sigma_range_from_config = cc.sigma_range_from_config;
    if (c.sigma_range_from_config) c.sigma_range_source = c.config_path;
  }
  if (c.auto_requested) c.node.auto_mode = true;
}

void applySetup(CalibratorProcessConfig& config, const SystemSetup& setup) {
  CalibratorConfig cc{config.calibrator, config.node, config.sigma_range_from_config, config.sigma_range_source};
  cc.applySetup(setup);
  config.calibrator = cc.calibrator;
  config.sigma_range_source = cc.sigma_range_source;
}

std::string CalibratorProcessConfig::toString() const {
  std::ostringstream s;
  s << "calibrator:\n" << calibrator.toString() << "  # sigma_range from " << sigma_range_source << "\n";
  s << "calibrator_node:\n" << node.toString();
  s << "process:\n";
  s << "  setup: " << (setup_path.empty() ? "(none)" : setup_path) << "\n";
  s << "  fleet: " << (fleet_path.empty() ? "(none)" : fleet_path) << "\n";
  if (!fleet_path.empty()) s << "  bus: " << bus << "\n";
  s << "  config: " << (config_path.empty() ? "(built-in defaults)" : config_path) << "\n";
  s << "  out_yaml: " << (out_yaml.empty() ? "(none)" : out_yaml) << "\n";
  s << "  state_dir: " << (state_dir.empty() ? "(none)" : state_dir) << "\n";
  s << "  pose_rate: " << pose_rate_hz << "  # [Hz], 0 = every pose\n";
  s << "  heartbeat: " << heartbeat_s << "  # [s] wall time\n";
  s << "  smoothed_poses: " << (smoothed_poses ? "true" : "false") << "  # POSE_SMOOTHED replaces the POSE taken\n";
  return s.str();
}

bool CalibrationYamlWriter::update(const std::vector<CalibrationResult>& results, int64_t attempts, bool force) {
  if (path_.empty()) return false;
  if (!force && attempts == written_attempts_) return false;
  namespace fs = std::filesystem;
  try {
    const fs::path p(path_);
    if (p.has_parent_path()) fs::create_directories(p.parent_path());
    const std::string tmp = path_ + ".tmp";
    writeCalibrationYaml(results, tmp);
    fs::rename(tmp, p);
  } catch (const std::exception& e) {
    spdlog::error("{}: cannot write the calibration results ({})", path_, e.what());
    return false;
  }
  written_attempts_ = attempts;
  return true;
}

}  // namespace meshnav::calib
