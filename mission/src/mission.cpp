#include "mission/mission.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/yaml_options.h"

namespace meshnav::mission {

const char* toString(MissionAction a) {
  switch (a) {
    case MissionAction::Collect: return "collect";
    case MissionAction::Calibrate: return "calibrate";
    case MissionAction::Remove: return "remove";
    case MissionAction::Abort: return "abort";
  }
  return "?";
}

std::string MissionStep::describe() const {
  std::ostringstream s;
  s << "t=" << t_s << " s " << toString(action) << " ";
  if (anchors.empty()) {
    s << "all";
  } else {
    for (size_t i = 0; i < anchors.size(); ++i) s << (i ? "," : "") << anchors[i];
  }
  return s.str();
}

namespace {

/// "file:line" of a node (yaml-cpp lines are 0-based).
std::string at(const std::string& source, const YAML::Node& n) {
  const auto m = n.Mark();
  return m.line >= 0 ? source + ":" + std::to_string(m.line + 1) : source;
}

[[noreturn]] void fail(const std::string& where, const std::string& key, const std::string& what) {
  throw std::runtime_error(where + ": key '" + key + "' " + what);
}

/// Text of a map key; a key that is not a plain scalar (a list, a map, null) is refused with its
/// file and line (yaml-cpp's own "bad conversion" names neither).
std::string keyText(const YAML::Node& k, const std::string& source, const std::string& in) {
  if (!k.IsScalar()) throw std::runtime_error(at(source, k) + ": a key of " + in + " is not a plain name");
  return k.Scalar();
}

MissionStep parseStep(const YAML::Node& n, size_t i, const std::string& source) {
  const std::string key = "steps[" + std::to_string(i) + "]";
  const std::string where = at(source, n);
  if (!n.IsMap()) fail(where, key, "must be a map {t: seconds, action: name, anchors: [ids]}");
  for (const auto& kv : n) {
    const auto k = keyText(kv.first, source, key);
    if (k != "t" && k != "action" && k != "anchors")
      throw std::runtime_error(at(source, kv.first) + ": unknown key '" + key + "." + k + "' (expected t, action, anchors)");
  }
  MissionStep s;
  s.line = n.Mark().line + 1;
  // t
  const YAML::Node t = n["t"];
  if (!t) fail(where, key + ".t", "is missing (time after the first sample [s])");
  try {
    s.t_s = t.as<double>();
  } catch (const std::exception&) {
    fail(at(source, t), key + ".t", "must be a number of seconds, got '" + (t.IsScalar() ? t.Scalar() : "?") + "'");
  }
  // Within kMaxTimeSeconds, so that adding the first sample's time cannot overflow later.
  if (!std::isfinite(s.t_s) || s.t_s < 0.0 || s.t_s > kMaxTimeSeconds)
    fail(at(source, t), key + ".t", "must be a finite time in [0, 4e12] s, got " + t.Scalar());
  // action
  const YAML::Node a = n["action"];
  if (!a) fail(where, key + ".action", "is missing (collect|calibrate|remove|abort)");
  const std::string name = a.IsScalar() ? a.Scalar() : "";
  if (name == "collect") {
    s.action = MissionAction::Collect;
  } else if (name == "calibrate") {
    s.action = MissionAction::Calibrate;
  } else if (name == "remove") {
    s.action = MissionAction::Remove;
  } else if (name == "abort") {
    s.action = MissionAction::Abort;
  } else {
    fail(at(source, a), key + ".action", "has unknown action '" + name + "' (collect|calibrate|remove|abort)");
  }
  // anchors
  if (const YAML::Node ids = n["anchors"]; ids && !ids.IsNull()) {
    if (!ids.IsSequence()) fail(at(source, ids), key + ".anchors", "must be a list of anchor ids, e.g. [106, 107]");
    for (size_t j = 0; j < ids.size(); ++j) {
      int64_t id = 0;
      try {
        id = ids[j].as<int64_t>();
      } catch (const std::exception&) {
        id = -1;
      }
      if (id <= 0 || id > INT32_MAX)
        fail(at(source, ids[j]), key + ".anchors[" + std::to_string(j) + "]",
             "must be a positive integer id, got '" + (ids[j].IsScalar() ? ids[j].Scalar() : "?") + "'");
      s.anchors.push_back(static_cast<SensorId>(id));
    }
  }
  if (s.action == MissionAction::Remove && s.anchors.empty())
    fail(where, key + ".anchors", "is required for action 'remove' (which instances to remove)");
  return s;
}

Mission parseRoot(const YAML::Node& root, const std::string& source) {
  Mission m;
  m.source = source;
  if (!root.IsMap()) throw std::runtime_error(source + ": expected a map with the key 'steps'");
  for (const auto& kv : root) {
    const auto k = keyText(kv.first, source, "the mission");
    if (k != "steps" && k != "collect_at_start")
      throw std::runtime_error(at(source, kv.first) + ": unknown key '" + k + "' (expected steps, collect_at_start)");
  }
  if (const YAML::Node c = root["collect_at_start"]) {
    try {
      m.collect_at_start = c.as<bool>();
    } catch (const std::exception&) {
      fail(at(source, c), "collect_at_start", "must be true or false");
    }
  }
  const YAML::Node steps = root["steps"];
  if (!steps) throw std::runtime_error(source + ": missing key 'steps' (a list of {t, action, anchors})");
  if (!steps.IsNull()) {
    if (!steps.IsSequence()) fail(at(source, steps), "steps", "must be a list of {t, action, anchors}");
    for (size_t i = 0; i < steps.size(); ++i) m.steps.push_back(parseStep(steps[i], i, source));
  }
  std::stable_sort(m.steps.begin(), m.steps.end(), [](const auto& a, const auto& b) { return a.t_s < b.t_s; });
  return m;
}

}  // namespace

Mission parseMission(const std::string& yaml_text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(source + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error (" + e.msg + ")");
  }
  YamlOptions::rejectDuplicateKeys(root, source);
  return parseRoot(root, source);
}

Mission loadMission(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the mission file");
  std::stringstream buf;
  buf << in.rdbuf();
  return parseMission(buf.str(), path);
}

}  // namespace meshnav::mission
