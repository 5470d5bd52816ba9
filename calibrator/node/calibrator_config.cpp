#include "calibrator/node/calibrator_config.h"

#include <spdlog/spdlog.h>
#include "common/yaml_options.h"

#include <cmath>
#include <stdexcept>

namespace meshnav::calib {

CalibratorConfig CalibratorConfig::load(const std::string& path) {
  CalibratorConfig c;
  if (path.empty()) return c;
  const YAML::Node root = YamlOptions::loadFile(path);
  if (!root || root.IsNull()) return c;  // empty file: defaults
  if (!root.IsMap()) throw std::runtime_error(path + ": expected a map with 'calibrator' and/or 'calibrator_node'");
  const YAML::Node& croot = root;  // const lookups: yaml-cpp's non-const operator[] inserts keys
  const bool sections = croot["calibrator"] || croot["calibrator_node"];
  YAML::Node cal;
  cal.reset(croot);  // (Node::operator= would overwrite the content of root)
  if (sections) {
    YamlOptions top(root, path);
    cal.reset(top.take("calibrator"));
    c.node = CalibratorNodeOptions::fromYaml(top.take("calibrator_node"), path);
    top.rejectUnknown();
  }
  c.calibrator = CalibratorOptions::fromYaml(cal, path);
  c.sigma_range_from_config = cal && cal.IsMap() && cal["sigma_range"];
  if (c.sigma_range_from_config) c.sigma_range_source = path;
  return c;
}

void CalibratorConfig::applySetup(const SystemSetup& setup) {
  if (sigma_range_from_config || !setup.noise.sigma_range_m) return;
  const double s = *setup.noise.sigma_range_m;
  if (!(s > 0.0) || !std::isfinite(s)) {
    spdlog::warn("setup noise.sigma_range = {} is not > 0: keeping σ_d = {} m", s, calibrator.sigma_range_m);
    return;
  }
  calibrator.sigma_range_m = s;
  sigma_range_source = "setup.yaml noise.sigma_range";
}

}  // namespace meshnav::calib
