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

const char* const kCalibratorProcessUsage =
    "calibrator --setup FILE [--config FILE] [options]\n"
    "  Calibrates new UWB anchors fly-by (DESIGN §5): subscribes RANGE, POSE, ANCHORS, CALIB_CMD;\n"
    "  publishes ANCHOR_INIT (position, covariance, pair biases) and CALIB_STATUS (per-anchor\n"
    "  state, counters; also a wall-clock heartbeat). Driven by a mission (CALIB_CMD) or, with\n"
    "  --auto, by itself. Malformed messages are counted per channel and reported in CALIB_STATUS.\n"
    "  --setup FILE       system setup (setup.yaml: tags, known anchors, pair biases, noise)\n"
    "  --config FILE      calibrator options YAML, `calibrator:` and `calibrator_node:` maps\n"
    "                     (default: built-in = config/calibrator.yaml); without\n"
    "                     calibrator.sigma_range, σ_d is setup.yaml's noise.sigma_range, else 0.1 m\n"
    "  --auto             calibrate automatically once an anchor's data suffices (when no mission\n"
    "                     drives the calibrator; sets calibrator_node.auto_mode)\n"
    "  --out-yaml FILE    write the calibration results (DESIGN §6 YAML) after every calibration\n"
    "                     and on exit\n"
    "  --pose-rate HZ     POSE decimation towards the calibrator (default 50; 0 = every pose)\n"
    "  --heartbeat S      wall seconds between heartbeat CALIB_STATUS (default 1)\n"
    "  --print-config     print the options and exit\n";

void declareCalibratorProcessOptions(Cli& cli) {
  cli.option("setup").option("out-yaml").option("pose-rate").option("heartbeat");
  cli.option("auto", false).option("print-config", false);
  cli.option("lcm-url").option("config").option("log-level");
}

namespace {

double nonNegative(const Cli& cli, const std::string& name, double fallback, bool strictly_positive) {
  double v = fallback;
  try {
    v = cli.getDouble(name, fallback);
  } catch (const std::exception&) {
    throw std::runtime_error("--" + name + ": not a number: '" + cli.get(name) + "'");
  }
  if (!std::isfinite(v) || v < 0.0 || (strictly_positive && v == 0.0))
    throw std::runtime_error("--" + name + " must be " + (strictly_positive ? "> 0" : ">= 0") + ", got '" +
                             cli.get(name) + "'");
  return v;
}

/// --config through the shared loader (calibrator/node/calibrator_config.h).
void loadConfigFile(CalibratorProcessConfig& c) {
  const CalibratorConfig cc = CalibratorConfig::load(c.config_path);
  c.calibrator = cc.calibrator;
  c.node = cc.node;
  c.sigma_range_from_config = cc.sigma_range_from_config;
}

}  // namespace

CalibratorProcessConfig calibratorProcessConfig(const Cli& cli) {
  CalibratorProcessConfig c;
  c.setup_path = cli.get("setup");
  c.config_path = cli.get("config");
  c.out_yaml = cli.get("out-yaml");
  c.print_config = cli.has("print-config");
  c.pose_rate_hz = nonNegative(cli, "pose-rate", 50.0, false);
  c.heartbeat_s = nonNegative(cli, "heartbeat", 1.0, true);
  if (!c.config_path.empty()) {
    loadConfigFile(c);
    if (c.sigma_range_from_config) c.sigma_range_source = c.config_path;
  }
  if (cli.has("auto")) c.node.auto_mode = true;
  return c;
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
  s << "  config: " << (config_path.empty() ? "(built-in defaults)" : config_path) << "\n";
  s << "  out_yaml: " << (out_yaml.empty() ? "(none)" : out_yaml) << "\n";
  s << "  pose_rate: " << pose_rate_hz << "  # [Hz], 0 = every pose\n";
  s << "  heartbeat: " << heartbeat_s << "  # [s] wall time\n";
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
