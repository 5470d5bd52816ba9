#include "calibrator/node/calibrator_node_options.h"

#include "common/yaml_options.h"

#include <sstream>
#include <stdexcept>

namespace meshnav::calib {

namespace {

/// Visits every option as (key, reference) so that reading and printing share one list.
template <typename Opts, typename F>
void visitOptions(Opts& o, F&& f) {
  f("auto_mode", o.auto_mode);
  f("auto_min_ranges", o.auto_min_ranges);
  f("auto_min_references", o.auto_min_references);
  f("auto_min_plane_spread", o.auto_min_plane_spread_m);
  f("auto_min_line_spread", o.auto_min_line_spread_m);
  f("auto_check_period", o.auto_check_period_s);
  f("auto_retry_period", o.auto_retry_period_s);
  f("retry_refused", o.retry_refused);
  f("collect_from_start", o.collect_from_start);
  f("history_window", o.history_window_s);
  f("max_ranges_per_anchor", o.max_ranges_per_anchor);
  f("status_period", o.status_period_s);
  f("time_max_offset", o.time.max_offset_s);
  f("time_rebase_after", o.time.rebase_after);
}

}  // namespace

CalibratorNodeOptions CalibratorNodeOptions::fromYaml(const YAML::Node& node, const std::string& where) {
  // The one rule of common/yaml_options.h (missing: default; unknown or bad: file and key).
  CalibratorNodeOptions o;
  YamlOptions yaml(node, where, "calibrator_node");
  visitOptions(o, [&](const char* key, auto& ref) { yaml.read(key, ref); });
  yaml.rejectUnknown();
  try {
    o.validate();
  } catch (const std::exception& e) {
    throw std::runtime_error(where + ": " + e.what());
  }
  return o;
}

void CalibratorNodeOptions::validate() const {
  auto require = [](bool ok, const char* key, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("key 'calibrator_node.") + key + "' must be " + what);
  };
  require(auto_min_ranges >= 1, "auto_min_ranges", ">= 1");
  require(auto_min_references >= 1, "auto_min_references", ">= 1");
  require(auto_min_plane_spread_m >= 0.0, "auto_min_plane_spread", ">= 0");
  require(auto_min_line_spread_m >= 0.0, "auto_min_line_spread", ">= 0");
  require(auto_check_period_s > 0.0, "auto_check_period", "> 0");
  require(auto_retry_period_s >= 0.0, "auto_retry_period", ">= 0");
  require(history_window_s > 0.0, "history_window", "> 0");
  require(max_ranges_per_anchor >= 1, "max_ranges_per_anchor", ">= 1");
  require(status_period_s > 0.0, "status_period", "> 0");
  require(time.max_offset_s > 0.0 && time.max_offset_s <= kMaxTimeSeconds, "time_max_offset", "> 0");
  require(time.rebase_after >= 1, "time_rebase_after", ">= 1");
}

std::string CalibratorNodeOptions::toString() const {
  std::ostringstream s;
  auto copy = *this;
  visitOptions(copy, [&](const char* key, auto& ref) {
    s << "  " << key << ": ";
    if constexpr (std::is_same_v<std::remove_reference_t<decltype(ref)>, bool>) {
      s << (ref ? "true" : "false");
    } else {
      s << ref;
    }
    s << "\n";
  });
  return s.str();
}

}  // namespace meshnav::calib
