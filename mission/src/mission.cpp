#include "mission/mission.h"

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>

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

/// A number at `n` (finite), refused with file, line and key otherwise.
double number(const YAML::Node& n, const std::string& key, const std::string& source) {
  double v = 0.0;
  try {
    v = n.as<double>();
  } catch (const std::exception&) {
    fail(at(source, n), key, "must be a number, got '" + (n.IsScalar() ? n.Scalar() : "?") + "'");
  }
  if (!std::isfinite(v)) fail(at(source, n), key, "must be finite, got " + n.Scalar());
  return v;
}

/// A list of `size` numbers at `n`.
Eigen::VectorXd numbers(const YAML::Node& n, size_t size, const std::string& key, const std::string& source) {
  if (!n.IsSequence() || n.size() != size)
    fail(at(source, n), key, "must be a list of " + std::to_string(size) + " numbers");
  Eigen::VectorXd v(static_cast<Eigen::Index>(size));
  for (size_t i = 0; i < size; ++i)
    v(static_cast<Eigen::Index>(i)) = number(n[i], key + "[" + std::to_string(i) + "]", source);
  return v;
}

/// Refuses a key of map `n` that is not in `known` (file, line, key).
void onlyKeys(const YAML::Node& n, const std::vector<std::string>& known, const std::string& key,
              const std::string& source) {
  std::string list;
  for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
  for (const auto& kv : n) {
    const auto k = keyText(kv.first, source, key);
    if (std::find(known.begin(), known.end(), k) == known.end())
      throw std::runtime_error(at(source, kv.first) + ": unknown key '" + key + "." + k + "' (expected " + list + ")");
  }
}

FlightPlan parseFlight(const YAML::Node& n, const std::string& source) {
  if (!n.IsMap()) fail(at(source, n), "flight", "must be a map (pad, takeoff_at, ..., waypoints)");
  onlyKeys(n,
           {"pad", "pad_yaw_deg", "takeoff_at", "takeoff_height", "speed", "vertical_speed", "acceleration",
            "yaw_rate_deg", "waypoints"},
           "flight", source);
  FlightPlan f;
  if (const YAML::Node p = n["pad"]) f.pad_xy_m = numbers(p, 2, "flight.pad", source);
  struct Scalar {
    const char* key;
    double* field;
    double min;  ///< values must be above (strictly, except for angles and times)
    bool strict;
  };
  const Scalar scalars[] = {{"pad_yaw_deg", &f.pad_yaw_deg, -1e9, false},
                            {"takeoff_at", &f.takeoff_at_s, 0.0, false},
                            {"takeoff_height", &f.takeoff_height_m, 0.0, true},
                            {"speed", &f.speed_m_s, 0.0, true},
                            {"vertical_speed", &f.vertical_speed_m_s, 0.0, true},
                            {"acceleration", &f.acceleration_m_s2, 0.0, true},
                            {"yaw_rate_deg", &f.yaw_rate_deg_s, 0.0, true}};
  for (const Scalar& sc : scalars) {
    const YAML::Node v = n[sc.key];
    if (!v) continue;
    *sc.field = number(v, std::string("flight.") + sc.key, source);
    if (sc.strict ? !(*sc.field > sc.min) : !(*sc.field >= sc.min))
      fail(at(source, v), std::string("flight.") + sc.key, std::string("must be ") + (sc.strict ? "> " : ">= ") +
                                                             std::to_string(sc.min) + ", got " + v.Scalar());
  }
  const YAML::Node wps = n["waypoints"];
  if (!wps || !wps.IsSequence() || wps.size() == 0)
    fail(at(source, wps ? wps : n), "flight.waypoints", "must be a non-empty list of {p: [x, y, z], yaw_deg, hold}");
  for (size_t i = 0; i < wps.size(); ++i) {
    const std::string key = "flight.waypoints[" + std::to_string(i) + "]";
    const YAML::Node w = wps[i];
    if (!w.IsMap()) fail(at(source, w), key, "must be a map {p: [x, y, z], yaw_deg, hold}");
    onlyKeys(w, {"p", "yaw_deg", "hold"}, key, source);
    Waypoint wp;
    wp.line = w.Mark().line + 1;
    if (!w["p"]) fail(at(source, w), key + ".p", "is missing ([x, y, z] in G [m])");
    wp.p_IinG = numbers(w["p"], 3, key + ".p", source);
    if (const YAML::Node y = w["yaw_deg"]) wp.yaw_deg = number(y, key + ".yaw_deg", source);
    if (const YAML::Node h = w["hold"]) {
      wp.hold_s = number(h, key + ".hold", source);
      if (wp.hold_s < 0.0) fail(at(source, h), key + ".hold", "must be >= 0 s");
    }
    f.waypoints.push_back(wp);
  }
  return f;
}

Mission parseRoot(const YAML::Node& root, const std::string& source) {
  Mission m;
  m.source = source;
  if (!root.IsMap()) throw std::runtime_error(source + ": expected a map with the key 'steps'");
  for (const auto& kv : root) {
    const auto k = keyText(kv.first, source, "the mission");
    if (k != "steps" && k != "collect_at_start" && k != "flight")
      throw std::runtime_error(at(source, kv.first) + ": unknown key '" + k +
                               "' (expected steps, collect_at_start, flight)");
  }
  if (const YAML::Node f = root["flight"]) m.flight = parseFlight(f, source);
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
