#include "calibrator/node/calibrator_node_options.h"

#include "common/options_list.h"

#include <sstream>
#include <stdexcept>
#include <variant>

namespace meshnav::calib {

namespace {

/// Where an option lives: a pointer to the member, of one of the types its options have.
using Ref = std::variant<double*, int*, bool*>;

template <auto... path>
constexpr auto at = &memberAt<CalibratorNodeOptions, Ref, path...>;

/// Every option as (key, member): the one list reading and printing share.
const OptionField<CalibratorNodeOptions, Ref> kFields[] = {
    {"auto_mode", at<&CalibratorNodeOptions::auto_mode>},
    {"auto_min_ranges", at<&CalibratorNodeOptions::auto_min_ranges>},
    {"auto_min_references", at<&CalibratorNodeOptions::auto_min_references>},
    {"auto_min_plane_spread", at<&CalibratorNodeOptions::auto_min_plane_spread_m>},
    {"auto_min_line_spread", at<&CalibratorNodeOptions::auto_min_line_spread_m>},
    {"auto_check_period", at<&CalibratorNodeOptions::auto_check_period_s>},
    {"auto_retry_period", at<&CalibratorNodeOptions::auto_retry_period_s>},
    {"retry_refused", at<&CalibratorNodeOptions::retry_refused>},
    {"collect_from_start", at<&CalibratorNodeOptions::collect_from_start>},
    {"history_window", at<&CalibratorNodeOptions::history_window_s>},
    {"max_ranges_per_anchor", at<&CalibratorNodeOptions::max_ranges_per_anchor>},
    {"status_period", at<&CalibratorNodeOptions::status_period_s>},
    {"time_max_offset", at<&CalibratorNodeOptions::time, &TimeGuardOptions::max_offset_s>},
    {"time_rebase_after", at<&CalibratorNodeOptions::time, &TimeGuardOptions::rebase_after>},
};

/// Visits every option as (key, field, unit).
template <typename Opts, typename F>
void visitOptions(Opts& o, F&& f) {
  forEachOption(o, kFields, f);
}

}  // namespace

CalibratorNodeOptions CalibratorNodeOptions::fromYaml(const YAML::Node& node, const std::string& where) {
  // The one rule of common/yaml_options.h (missing: default; unknown or bad: file and key).
  YamlOptions yaml(node, where, "calibrator_node");
  return readOptionsList<CalibratorNodeOptions>(yaml, [](auto& o, auto&& f) { visitOptions(o, f); });
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
  return printOptionsList(*this, [](auto& o, auto&& f) { visitOptions(o, f); });
}

}  // namespace meshnav::calib
