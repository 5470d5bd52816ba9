/// @file peer_router_state.cpp
/// @brief The peer_router's restart journal: write and read (peer_router_state.h).

#include "pipeline/peer_router_state.h"

#include <yaml-cpp/yaml.h>

#include <stdexcept>

#include "common/atomic_file.h"
#include "common/time.h"
#include "common/yaml_options.h"

namespace meshnav::pipeline {

namespace {
constexpr int kLayout = 1;

/// A data time's limit [µs]: the project's ±kMaxTimeSeconds (common/time.h), so that the
/// difference of two of them fits an int64.
bool inRange(int64_t us) {
  constexpr auto kMaxUs = static_cast<int64_t>(kMaxTimeSeconds * 1e6);
  return us >= -kMaxUs && us <= kMaxUs;
}
}  // namespace

void writePeerRouterState(const std::string& path, const PeerRouterState& state, const std::vector<std::string>& names) {
  if (state.provenance.size() != names.size())
    throw std::runtime_error(path + ": " + std::to_string(state.provenance.size()) + " vehicles' provenance for a fleet of " +
                             std::to_string(names.size()));
  YAML::Emitter y;
  y << YAML::BeginMap;
  y << YAML::Key << "layout" << YAML::Value << kLayout;
  y << YAML::Key << "t_us" << YAML::Value << state.t.us;
  y << YAML::Key << "holds" << YAML::Value << YAML::BeginMap;
  for (size_t v = 0; v < names.size(); ++v) {
    y << YAML::Key << names[v] << YAML::Value << YAML::Flow << YAML::BeginMap;
    for (const auto& [u, since] : state.provenance[v]) {
      if (u >= names.size()) throw std::runtime_error(path + ": vehicle index " + std::to_string(u) + " is not of the fleet");
      y << YAML::Key << names[u] << YAML::Value << since.us;
    }
    y << YAML::EndMap;
  }
  y << YAML::EndMap << YAML::EndMap;
  writeFileAtomically(path, [&](std::ostream& os) {
    os << "# meshnav peer_router state (docs/formats.md): whose information each vehicle's estimate holds\n"
       << "# holds: vehicle -> {vehicle whose information it absorbed: data time it entered [us]}\n"
       << y.c_str() << "\n";
  });
}

PeerRouterState readPeerRouterState(const std::string& path, const std::vector<std::string>& names) {
  YamlOptions root(YamlOptions::loadFile(path), path);
  int layout = 0;
  root.require("layout", layout);
  if (layout != kLayout) root.fail("layout", "must be " + std::to_string(kLayout) + ", got " + std::to_string(layout));
  PeerRouterState s;
  root.require("t_us", s.t.us);
  if (!inRange(s.t.us)) root.fail("t_us", "must be within +-" + std::to_string(static_cast<long long>(kMaxTimeSeconds)) + " s");
  if (!root.has("holds")) root.fail("holds", "is missing");
  const YAML::Node holds_node = root.take("holds");
  if (!holds_node.IsMap()) root.fail("holds", "must be a map of vehicle names");
  YamlOptions holds(holds_node, path, "holds");
  s.provenance.assign(names.size(), {});
  for (size_t v = 0; v < names.size(); ++v) {
    const YAML::Node entry = holds.take(names[v]);
    if (!entry || entry.IsNull()) continue;
    if (!entry.IsMap()) holds.fail(names[v], "must be a map {vehicle: data time [us]}");
    YamlOptions of(entry, path, holds.fullKey(names[v]));
    for (size_t u = 0; u < names.size(); ++u) {
      if (!of.has(names[u])) continue;
      if (u == v) of.fail(names[u], "a vehicle does not hold its own information");
      Timestamp since;
      of.read(names[u], since.us);
      if (since > s.t) of.fail(names[u], "is after the journal's t_us: an entry cannot be newer than its journal");
      if (!inRange(since.us)) of.fail(names[u], "must be within +-" + std::to_string(static_cast<long long>(kMaxTimeSeconds)) + " s");
      s.provenance[v].emplace(u, since);
    }
    of.rejectUnknown();
  }
  holds.rejectUnknown();
  root.rejectUnknown();
  return s;
}

}  // namespace meshnav::pipeline
