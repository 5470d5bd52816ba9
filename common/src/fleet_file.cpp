/// @file fleet_file.cpp
/// @brief The fleet file reader (docs/fleet.md).

#include "common/fleet_file.h"

#include <algorithm>
#include <filesystem>
#include <set>

#include "common/yaml_options.h"

namespace meshnav {

bool isVehicleName(std::string_view s) {
  if (s.empty() || s.size() > 64) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
}

std::vector<FleetEntry> loadFleetFile(const std::string& path) {
  YamlOptions root(YamlOptions::loadFile(path), path);
  const YAML::Node list = root.take("vehicles");
  root.rejectUnknown();
  if (!list || list.IsNull()) root.fail("vehicles", "is missing: a fleet file lists its vehicles (docs/fleet.md)");
  if (!list.IsSequence() || list.size() == 0) root.fail("vehicles", "must be a non-empty list of {name, dataset}");
  const std::filesystem::path base = std::filesystem::path(path).parent_path();
  std::vector<FleetEntry> out;
  std::set<std::string> names;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string key = "vehicles[" + std::to_string(i) + "]";
    YamlOptions v(list[i], path, key);
    FleetEntry e;
    v.require("name", e.name);
    v.require("dataset", e.dataset);
    v.rejectUnknown();
    if (!isVehicleName(e.name)) v.fail("name", "'" + e.name + "' must be 1-64 letters, digits, '_' or '-' (it names a folder)");
    if (!names.insert(e.name).second) v.fail("name", "'" + e.name + "' is the name of an earlier vehicle");
    if (e.dataset.empty()) v.fail("dataset", "is empty");
    const std::filesystem::path d(e.dataset);
    e.dataset = (d.is_absolute() ? d : base / d).lexically_normal().string();
    out.push_back(std::move(e));
  }
  return out;
}

}  // namespace meshnav
