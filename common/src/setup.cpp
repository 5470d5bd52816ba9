#include "common/setup.h"

#include "common/atomic_file.h"

#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "common/plausibility.h"
#include "common/yaml_options.h"

namespace meshnav {

namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what);
}

Eigen::Vector3d vec3(const YAML::Node& n, const std::string& path, const std::string& key) {
  if (!n || !n.IsSequence() || n.size() != 3) fail(path, "key '" + key + "' must be a list of 3 numbers [m]");
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) {
    try {
      v[i] = n[i].as<double>();
    } catch (const YAML::Exception&) {
      fail(path, "key '" + key + "' must be a list of 3 numbers [m], got '" + yamlText(n[i]) + "'");
    }
    if (!std::isfinite(v[i])) fail(path, "key '" + key + "' must be a list of 3 finite numbers [m], got '" + yamlText(n[i]) + "'");
  }
  return v;
}

double num(const YAML::Node& n, const std::string& path, const std::string& key) {
  if (!n || !n.IsScalar()) fail(path, "missing or non-scalar key '" + key + "'");
  double v = 0.0;
  try {
    v = n.as<double>();
  } catch (const YAML::Exception&) {
    fail(path, "key '" + key + "' must be a number, got '" + n.Scalar() + "'");
  }
  if (!std::isfinite(v)) fail(path, "key '" + key + "' must be a finite number, got '" + n.Scalar() + "'");
  return v;
}

/// A device id (a map key or list entry): an integer in 0..INT32_MAX.
SensorId deviceId(const YAML::Node& n, const std::string& path, const std::string& key) {
  int64_t id = -1;
  try {
    id = n.as<int64_t>();
  } catch (const YAML::Exception&) {
  }
  if (id < 0 || id > INT32_MAX)
    fail(path, "key '" + key + "': id '" + yamlText(n) + "' is not a device id (an integer in 0.." +
                   std::to_string(INT32_MAX) + ")");
  return static_cast<SensorId>(id);
}

std::map<SensorId, Eigen::Vector3d> idVecMap(const YAML::Node& n, const std::string& path, const std::string& key) {
  std::map<SensorId, Eigen::Vector3d> out;
  if (!n) return out;
  if (!n.IsMap()) fail(path, "key '" + key + "' must be a map {id: [x, y, z]}");
  for (const auto& kv : n) {
    const SensorId id = deviceId(kv.first, path, key);
    if (out.count(id)) fail(path, "key '" + key + "." + std::to_string(id) + "' is given twice");
    out[id] = vec3(kv.second, path, key + "." + std::to_string(id));
  }
  return out;
}

/// The published toolbox config writes flow maps as `{0:[1, 2, 3]}` (no space after the colon),
/// which YAML reads as one plain scalar. Insert the space so that such files load as intended.
std::string normalizeFlowMaps(const std::string& text) {
  static const std::regex re(R"(([0-9A-Za-z_]):\[)");
  return std::regex_replace(text, re, "$1: [");
}

YAML::Node loadYamlFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail(path, "cannot open file");
  std::stringstream ss;
  ss << in.rdbuf();
  YAML::Node root;
  try {
    root = YAML::Load(normalizeFlowMaps(ss.str()));
  } catch (const YAML::Exception& e) {
    fail(path, std::string("YAML syntax error: ") + e.what());
  }
  YamlOptions::rejectDuplicateKeys(root, path);  // (normalizeFlowMaps keeps the lines)
  return root;
}

std::vector<PairBias> readPairBiases(const YAML::Node& n, const std::string& path, const std::string& key) {
  std::vector<PairBias> out;
  if (!n) return out;
  if (!n.IsSequence()) fail(path, "key '" + key + "' must be a list of {ids: [a, b], gamma, beta, sigma}");
  int i = 0;
  std::map<std::pair<SensorId, SensorId>, std::string> seen;  // pair → the key that gave it
  for (const auto& e : n) {
    const std::string k = key + "[" + std::to_string(i++) + "]";
    if (!e.IsMap()) fail(path, "key '" + k + "' must be a map {ids: [a, b], gamma, beta, sigma}");
    YamlOptions entry(e, path, k);
    const auto ids = entry.take("ids");
    if (!ids || !ids.IsSequence() || ids.size() != 2) fail(path, "key '" + k + ".ids' must be [a, b]");
    PairBias b;  // defaults: gamma 0, beta 1, sigma 0.1, no uncertainty of gamma and beta
    b.a = deviceId(ids[0], path, k + ".ids");
    b.b = deviceId(ids[1], path, k + ".ids");
    if (b.a == b.b) fail(path, "key '" + k + ".ids' names the same device twice");
    entry.read("gamma", b.gamma_m);
    entry.read("beta", b.beta);
    entry.read("sigma", b.sigma_m);
    entry.read("sigma_gamma", b.sigma_gamma_m);
    entry.read("sigma_beta", b.sigma_beta);
    entry.rejectUnknown();
    if (b.sigma_m <= 0.0) entry.fail("sigma", "must be > 0 [m]");
    if (b.beta <= 0.0) entry.fail("beta", "must be > 0 [-]");
    if (b.sigma_gamma_m < 0.0) entry.fail("sigma_gamma", "must be >= 0 [m]");
    if (b.sigma_beta < 0.0) entry.fail("sigma_beta", "must be >= 0 [-]");
    // One model per pair (symmetric in a, b): a second entry would be read by some users and not others.
    if (const auto [it, added] = seen.emplace(pairKey(b.a, b.b), k); !added)
      fail(path, "key '" + k + ".ids' names the pair " + std::to_string(b.a) + "–" + std::to_string(b.b) +
                     " of '" + it->second + "' again");
    out.push_back(b);
  }
  return out;
}

void emitVec(YAML::Emitter& e, const Eigen::Vector3d& v) {
  e << YAML::Flow << YAML::BeginSeq << v.x() << v.y() << v.z() << YAML::EndSeq;
}

/// `key: {id: [x, y, z], ...}` with `comment`: the counterpart of idVecMap.
void emitIdVecMap(YAML::Emitter& e, const char* key, const char* comment,
                  const std::map<SensorId, Eigen::Vector3d>& m) {
  e << YAML::Key << key << YAML::Comment(comment) << YAML::Value << YAML::BeginMap;
  for (const auto& [id, p] : m) {
    e << YAML::Key << id << YAML::Value;
    emitVec(e, p);
  }
  e << YAML::EndMap;
}

void emitPairBiases(YAML::Emitter& e, const std::vector<PairBias>& biases) {
  e << YAML::BeginSeq;
  for (const auto& b : biases) {
    e << YAML::Flow << YAML::BeginMap;
    e << YAML::Key << "ids" << YAML::Value << YAML::Flow << YAML::BeginSeq << b.a << b.b << YAML::EndSeq;
    e << YAML::Key << "gamma" << YAML::Value << b.gamma_m;
    e << YAML::Key << "beta" << YAML::Value << b.beta;
    e << YAML::Key << "sigma" << YAML::Value << b.sigma_m;
    if (b.sigma_gamma_m > 0) e << YAML::Key << "sigma_gamma" << YAML::Value << b.sigma_gamma_m;
    if (b.sigma_beta > 0) e << YAML::Key << "sigma_beta" << YAML::Value << b.sigma_beta;
    e << YAML::EndMap;
  }
  e << YAML::EndSeq;
}

void writeText(const std::string& path, const std::string& header, const char* body) {
  writeFileAtomically(path, [&](std::ostream& out) { out << header << body << "\n"; });
}

/// Every id names one device: a collision is an error naming both roles. imu_id, baro_id,
/// height_id and uwb_clock_id left out of the file default to 1, 2, 3 and 4; when a tag or anchor of
/// the file, or an id given or placed before it in that order, uses that id, the smallest free id is
/// taken instead (the published toolbox's config.yaml numbers anchors 1, 2, 3).
void checkIds(SystemSetup& s, const std::string& path, const YamlOptions& y) {
  auto role = [&](SensorId id) -> std::string {
    if (s.rel_tag_positions.count(id)) return "a tag (rel_tag_positions." + std::to_string(id) + ")";
    if (s.abs_anchor_positions.count(id)) return "an anchor (abs_anchor_positions." + std::to_string(id) + ")";
    return "";
  };
  for (const auto& [id, p] : s.rel_tag_positions)
    if (s.abs_anchor_positions.count(id)) fail(path, "id " + std::to_string(id) + " is both a tag and an anchor");
  const std::array<std::pair<const char*, SensorId*>, 4> ids{{{"imu_id", &s.imu_id},
                                                              {"baro_id", &s.baro_id},
                                                              {"height_id", &s.height_id},
                                                              {"uwb_clock_id", &s.uwb_clock_id}}};
  // A default id makes way for the ids given in the file and for the defaults placed before it.
  auto taken = [&](size_t i, SensorId id) {
    for (size_t j = 0; j < ids.size(); ++j)
      if (j != i && *ids[j].second == id && (y.has(ids[j].first) || j < i)) return true;
    return false;
  };
  for (size_t i = 0; i < ids.size(); ++i) {
    auto [key, id] = ids[i];
    const bool given = y.has(key);
    if (*id < 0) fail(path, std::string("key '") + key + "' must be an id >= 0, got " + std::to_string(*id));
    const std::string other = role(*id);
    if (other.empty() && (given || !taken(i, *id))) continue;
    if (given) fail(path, std::string("key '") + key + "' = " + std::to_string(*id) + " is also " + other);
    SensorId moved = 1;
    while (!role(moved).empty() || taken(i, moved)) ++moved;
    spdlog::info("{}: {} not given and its default {} is {}: using {}", path, key, *id,
                 other.empty() ? std::string("another sensor's id") : other, moved);
    *id = moved;
  }
  for (size_t i = 0; i < ids.size(); ++i)
    for (size_t j = i + 1; j < ids.size(); ++j)
      if (*ids[i].second == *ids[j].second)
        fail(path, std::string("key '") + ids[i].first + "' and key '" + ids[j].first + "' are the same id " +
                       std::to_string(*ids[i].second));
}

/// `flight_volume: {min_m, max_m}` (both required), or none.
std::optional<FlightVolume> readFlightVolume(YamlOptions& y) {
  if (!y.has("flight_volume")) return std::nullopt;
  FlightVolume v;  // no sensible default: both corners required
  y.require("flight_volume.min_m", v.min_m);
  y.require("flight_volume.max_m", v.max_m);
  if (!v.min_m.allFinite() || !v.max_m.allFinite() || !((v.max_m - v.min_m).minCoeff() > 0.0) ||
      (v.max_m - v.min_m).maxCoeff() > plausible::kMaxHeight_m * 100.0)
    y.fail("flight_volume", "min_m must be below max_m on every axis, both finite and at most 10 km apart [m]");
  return v;
}

/// `abs_anchor_sigmas: {id: sigma_m}` of anchors listed in abs_anchor_positions.
void readAnchorSigmas(const YAML::Node& sig, const std::string& path, SystemSetup& s) {
  if (!sig || sig.IsNull()) return;
  if (!sig.IsMap()) fail(path, "key 'abs_anchor_sigmas' must be a map {id: sigma_m}");
  for (const auto& kv : sig) {
    const SensorId id = deviceId(kv.first, path, "abs_anchor_sigmas");
    if (!s.abs_anchor_positions.count(id)) {
      fail(path, "key 'abs_anchor_sigmas." + std::to_string(id) + "' names an anchor missing in abs_anchor_positions");
    }
    const double v = num(kv.second, path, "abs_anchor_sigmas." + std::to_string(id));
    if (v < 0) fail(path, "key 'abs_anchor_sigmas." + std::to_string(id) + "' must be >= 0 [m]");
    s.abs_anchor_sigmas_m[id] = v;
  }
}

/// `noise:` (every key optional: the estimator's and simulator's own defaults apply).
NoiseFigures readNoise(YamlOptions& y) {
  NoiseFigures n;
  y.read("noise.sigma_range", n.sigma_range_m);
  y.read("noise.sigma_gamma", n.sigma_gamma_m);
  y.read("noise.range_correlation_time", n.range_correlation_time_s);
  y.read("noise.imu_acc_noise_density", n.imu_acc_noise_density);
  y.read("noise.imu_gyro_noise_density", n.imu_gyro_noise_density);
  y.read("noise.imu_acc_bias_rw", n.imu_acc_bias_rw);
  y.read("noise.imu_gyro_bias_rw", n.imu_gyro_bias_rw);
  y.read("noise.imu_acc_bias_sigma", n.imu_acc_bias_sigma);
  y.read("noise.imu_gyro_bias_sigma", n.imu_gyro_bias_sigma);
  y.read("noise.baro_pressure_sigma", n.baro_pressure_sigma_pa);
  for (const auto& [key, v] : {std::pair{"noise.sigma_range", n.sigma_range_m},
                               {"noise.imu_acc_bias_sigma", n.imu_acc_bias_sigma},
                               {"noise.imu_gyro_bias_sigma", n.imu_gyro_bias_sigma},
                               {"noise.imu_acc_noise_density", n.imu_acc_noise_density},
                               {"noise.imu_gyro_noise_density", n.imu_gyro_noise_density},
                               {"noise.baro_pressure_sigma", n.baro_pressure_sigma_pa}})
    if (v && !(*v > 0.0)) y.fail(key, "must be > 0");
  if (n.sigma_gamma_m && !(*n.sigma_gamma_m >= 0.0 && *n.sigma_gamma_m <= 10.0))
    y.fail("noise.sigma_gamma", "must be in [0, 10] [m]");
  if (n.range_correlation_time_s && !(*n.range_correlation_time_s >= 0.0 && *n.range_correlation_time_s <= 60.0))
    y.fail("noise.range_correlation_time", "must be in [0, 60] [s]");
  for (const auto& [key, v] : {std::pair{"noise.imu_acc_bias_rw", n.imu_acc_bias_rw},
                               {"noise.imu_gyro_bias_rw", n.imu_gyro_bias_rw}})
    if (v && !(*v >= 0.0)) y.fail(key, "must be >= 0");
  return n;
}

}  // namespace

std::optional<PairBias> SystemSetup::findPairBias(SensorId a, SensorId b) const {
  for (const auto& pb : pair_biases) {
    if ((pb.a == a && pb.b == b) || (pb.a == b && pb.b == a)) return pb;
  }
  return std::nullopt;
}

SystemSetup loadSetup(const std::string& path) {
  const YAML::Node root = loadYamlFile(path);
  if (!root.IsMap()) fail(path, "top level must be a map");
  // The one rule of common/yaml_options.h: unknown keys and bad values name the file and the key,
  // a missing key keeps its default (docs/configuration.md).
  YamlOptions y(root, path);
  for (const char* section : {"baro", "height", "initial_pose", "noise", "uwb_clock"})
    if (root[section] && root[section].IsNull()) y.take(section);  // `key:` with nothing: defaults
  for (const char* ignored : {"tag_topics", "anchor_topics", "pose_topics"}) y.take(ignored);  // toolbox config.yaml
  SystemSetup s;
  y.read("imu_id", s.imu_id);
  y.read("baro_id", s.baro_id);
  y.read("height_id", s.height_id);
  y.read("uwb_clock_id", s.uwb_clock_id);
  y.read("uwb_clock.offset_s", s.uwb_clock.offset_s);
  y.read("uwb_clock.sigma_s", s.uwb_clock.sigma_s);
  if (!(std::abs(s.uwb_clock.offset_s) <= 1.0))
    y.fail("uwb_clock.offset_s", "must be the UWB stamps' delay against the IMU clock within [-1, 1] s");
  if (s.uwb_clock.sigma_s && !(*s.uwb_clock.sigma_s >= 0.0 && *s.uwb_clock.sigma_s <= 1.0))
    y.fail("uwb_clock.sigma_s", "must be in [0, 1] s (0: the offset is known exactly)");
  s.rel_tag_positions = idVecMap(y.take("rel_tag_positions"), path, "rel_tag_positions");
  s.abs_anchor_positions = idVecMap(y.take("abs_anchor_positions"), path, "abs_anchor_positions");
  readAnchorSigmas(y.take("abs_anchor_sigmas"), path, s);
  s.pair_biases = readPairBiases(y.take("pair_biases"), path, "pair_biases");
  y.read("baro.p_IP", s.baro_p_IP);
  y.read("baro.reference_pressure", s.baro_reference_pressure_pa);
  if (s.baro_reference_pressure_pa &&
      !(*s.baro_reference_pressure_pa >= plausible::kMinPressure_pa && *s.baro_reference_pressure_pa <= plausible::kMaxPressure_pa))
    y.fail("baro.reference_pressure", "must be a plausible pressure in Pa (or null: taken on the ground)");
  y.read("height.p_IH", s.height_p_IH);
  if (y.has("initial_pose")) {
    InitialPose p;  // p_IinG and yaw_deg have no sensible default: required
    y.require("initial_pose.p_IinG", p.p_IinG);
    y.require("initial_pose.yaw_deg", p.yaw_deg);
    y.read("initial_pose.sigma_p", p.sigma_p_m);
    y.read("initial_pose.sigma_yaw_deg", p.sigma_yaw_deg);
    if (p.sigma_p_m <= 0) y.fail("initial_pose.sigma_p", "must be > 0 [m]");
    if (p.sigma_yaw_deg <= 0) y.fail("initial_pose.sigma_yaw_deg", "must be > 0 [deg]");
    s.initial_pose = p;
  }
  if (y.has("carried_height")) {
    CarriedHeight c;  // height_m has no sensible default: required
    y.require("carried_height.height_m", c.height_m);
    y.read("carried_height.sigma_m", c.sigma_m);
    if (!(c.height_m > 0.0 && c.height_m < plausible::kMaxHeight_m))
      y.fail("carried_height.height_m", "must be a height above the floor in (0, 100) m");
    if (!(c.sigma_m > 0.0)) y.fail("carried_height.sigma_m", "must be > 0 [m]");
    s.carried_height = c;
  }
  s.flight_volume = readFlightVolume(y);
  // A volume in another frame than the anchors would rule the true pose out: every known anchor
  // must lie in it (within 1 m: anchors hang on its walls and ceiling).
  for (const auto& [id, p] : s.abs_anchor_positions)
    if (s.flight_volume && s.flight_volume->distanceOutside(p) > 1.0)
      y.fail("flight_volume", "does not hold known anchor " + std::to_string(id) + " (" +
                                  std::to_string(s.flight_volume->distanceOutside(p)) +
                                  " m outside): the volume and the anchors must be in the same frame G [m]");
  s.noise = readNoise(y);
  y.rejectUnknown();
  checkIds(s, path, y);
  return s;
}

void saveSetup(const SystemSetup& s, const std::string& path) {
  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "imu_id" << YAML::Value << s.imu_id;
  e << YAML::Key << "baro_id" << YAML::Value << s.baro_id;
  emitIdVecMap(e, "rel_tag_positions", "tag position in the IMU frame [m]", s.rel_tag_positions);
  emitIdVecMap(e, "abs_anchor_positions", "known anchors in the world frame [m]", s.abs_anchor_positions);
  if (!s.abs_anchor_sigmas_m.empty()) {
    e << YAML::Key << "abs_anchor_sigmas" << YAML::Comment("position sigma of uncertain known anchors [m]")
      << YAML::Value << YAML::BeginMap;
    for (const auto& [id, v] : s.abs_anchor_sigmas_m) e << YAML::Key << id << YAML::Value << v;
    e << YAML::EndMap;
  }
  e << YAML::Key << "pair_biases" << YAML::Comment("z = beta*d + gamma + noise; gamma, sigma [m]") << YAML::Value;
  emitPairBiases(e, s.pair_biases);
  e << YAML::Key << "baro" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "p_IP" << YAML::Value;
  emitVec(e, s.baro_p_IP);
  e << YAML::Key << "reference_pressure" << YAML::Comment("[Pa]; null: taken on the ground at start")
    << YAML::Value;
  if (s.baro_reference_pressure_pa) e << *s.baro_reference_pressure_pa;
  else e << YAML::Null;
  e << YAML::EndMap;
  if (s.height_id != SystemSetup{}.height_id || !s.height_p_IH.isZero()) {  // only when not the defaults
    e << YAML::Key << "height_id" << YAML::Value << s.height_id;
    e << YAML::Key << "height" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "p_IH" << YAML::Comment("downward rangefinder in the IMU frame [m]") << YAML::Value;
    emitVec(e, s.height_p_IH);
    e << YAML::EndMap;
  }
  if (s.uwb_clock_id != SystemSetup{}.uwb_clock_id) e << YAML::Key << "uwb_clock_id" << YAML::Value << s.uwb_clock_id;
  if (s.uwb_clock.offset_s != 0.0 || s.uwb_clock.sigma_s) {  // only when not the defaults
    e << YAML::Key << "uwb_clock" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "offset_s" << YAML::Value << s.uwb_clock.offset_s
      << YAML::Comment("UWB stamps' delay against the IMU clock: a range stamped t was measured at t - offset_s [s]");
    if (s.uwb_clock.sigma_s)
      e << YAML::Key << "sigma_s" << YAML::Value << *s.uwb_clock.sigma_s
        << YAML::Comment("its prior sigma [s]; 0: known exactly");
    e << YAML::EndMap;
  }
  if (s.initial_pose) {
    const auto& p = *s.initial_pose;
    e << YAML::Key << "initial_pose" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "p_IinG" << YAML::Value;
    emitVec(e, p.p_IinG);
    e << YAML::Key << "yaw_deg" << YAML::Value << p.yaw_deg;
    e << YAML::Key << "sigma_p" << YAML::Value << p.sigma_p_m;
    e << YAML::Key << "sigma_yaw_deg" << YAML::Value << p.sigma_yaw_deg;
    e << YAML::EndMap;
  }
  if (s.carried_height) {
    e << YAML::Key << "carried_height"
      << YAML::Comment("hand-held rig: usual IMU height above the floor (z = 0) and its 1 sigma [m]") << YAML::Value
      << YAML::BeginMap;
    e << YAML::Key << "height_m" << YAML::Value << s.carried_height->height_m;
    e << YAML::Key << "sigma_m" << YAML::Value << s.carried_height->sigma_m;
    e << YAML::EndMap;
  }
  if (s.flight_volume) {
    e << YAML::Key << "flight_volume" << YAML::Comment("the box in G the vehicle stays in (hall, geofence) [m]")
      << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "min_m" << YAML::Value;
    emitVec(e, s.flight_volume->min_m);
    e << YAML::Key << "max_m" << YAML::Value;
    emitVec(e, s.flight_volume->max_m);
    e << YAML::EndMap;
  }
  const auto& n = s.noise;
  if (n.sigma_range_m || n.sigma_gamma_m || n.range_correlation_time_s || n.imu_acc_noise_density || n.imu_gyro_noise_density || n.imu_acc_bias_rw ||
      n.imu_gyro_bias_rw || n.imu_acc_bias_sigma || n.imu_gyro_bias_sigma || n.baro_pressure_sigma_pa) {
    e << YAML::Key << "noise" << YAML::Value << YAML::BeginMap;
    auto put = [&](const char* k, const std::optional<double>& v, const char* unit) {
      if (v) e << YAML::Key << k << YAML::Value << *v << YAML::Comment(unit);
    };
    put("sigma_range", n.sigma_range_m, "m");
    put("sigma_gamma", n.sigma_gamma_m, "m, constant bias of a pair not in pair_biases (1 sigma); 0 = calibrated ranges");
    put("range_correlation_time", n.range_correlation_time_s, "s, of a pair's range error; 0 = independent errors");
    put("imu_acc_noise_density", n.imu_acc_noise_density, "m/s^2/sqrt(Hz)");
    put("imu_gyro_noise_density", n.imu_gyro_noise_density, "rad/s/sqrt(Hz)");
    put("imu_acc_bias_rw", n.imu_acc_bias_rw, "m/s^3/sqrt(Hz)");
    put("imu_gyro_bias_rw", n.imu_gyro_bias_rw, "rad/s^2/sqrt(Hz)");
    put("imu_acc_bias_sigma", n.imu_acc_bias_sigma, "m/s^2, bias at switch-on (1 sigma)");
    put("imu_gyro_bias_sigma", n.imu_gyro_bias_sigma, "rad/s, bias at switch-on (1 sigma)");
    put("baro_pressure_sigma", n.baro_pressure_sigma_pa, "Pa");
    e << YAML::EndMap;
  }
  e << YAML::EndMap;
  writeText(path, "# meshnav system setup: what the system may know (docs/formats.md)\n", e.c_str());
}

Truth loadTruth(const std::string& path) {
  const YAML::Node root = loadYamlFile(path);
  if (!root.IsMap()) fail(path, "top level must be a map");
  Truth t;
  t.anchor_positions = idVecMap(root["anchor_positions"], path, "anchor_positions");
  t.pair_biases = readPairBiases(root["pair_biases"], path, "pair_biases");
  if (const auto sc = root["scalars"]; sc && sc.IsMap()) {
    for (const auto& kv : sc) t.scalars[kv.first.as<std::string>()] = num(kv.second, path, "scalars." + kv.first.as<std::string>());
  }
  if (const auto f = root["truth_frame"]; f && !f.IsNull()) {
    if (!f.IsScalar()) fail(path, "key 'truth_frame' must be a frame name");
    t.truth_frame = f.Scalar();
  }
  if (const auto a = root["align_required"]; a && !a.IsNull()) {
    try {
      t.align_required = a.as<bool>();
    } catch (const YAML::Exception&) {
      fail(path, "key 'align_required' must be true or false, got '" + (a.IsScalar() ? a.Scalar() : "?") + "'");
    }
  }
  return t;
}

void saveTruth(const Truth& t, const std::string& path) {
  YAML::Emitter e;
  e << YAML::BeginMap;
  emitIdVecMap(e, "anchor_positions", "all anchors, world frame [m]", t.anchor_positions);
  e << YAML::Key << "pair_biases" << YAML::Value;
  emitPairBiases(e, t.pair_biases);
  e << YAML::Key << "scalars" << YAML::Value << YAML::BeginMap;
  for (const auto& [k, v] : t.scalars) e << YAML::Key << k << YAML::Value << v;
  e << YAML::EndMap;
  if (!t.truth_frame.empty()) e << YAML::Key << "truth_frame" << YAML::Value << t.truth_frame;
  if (t.align_required) e << YAML::Key << "align_required" << YAML::Value << true;
  e << YAML::EndMap;
  writeText(path, "# meshnav simulated truth: evaluation only, never read by estimator or calibrator\n", e.c_str());
}

}  // namespace meshnav
