#include "common/setup.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>

namespace meshnav {

namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what);
}

Eigen::Vector3d vec3(const YAML::Node& n, const std::string& path, const std::string& key) {
  if (!n || !n.IsSequence() || n.size() != 3) fail(path, "key '" + key + "' must be a list of 3 numbers [m]");
  try {
    return {n[0].as<double>(), n[1].as<double>(), n[2].as<double>()};
  } catch (const YAML::Exception&) {
    fail(path, "key '" + key + "' must be a list of 3 numbers [m]");
  }
}

double num(const YAML::Node& n, const std::string& path, const std::string& key) {
  if (!n || !n.IsScalar()) fail(path, "missing or non-scalar key '" + key + "'");
  try {
    return n.as<double>();
  } catch (const YAML::Exception&) {
    fail(path, "key '" + key + "' must be a number, got '" + n.Scalar() + "'");
  }
}

std::map<SensorId, Eigen::Vector3d> idVecMap(const YAML::Node& n, const std::string& path, const std::string& key) {
  std::map<SensorId, Eigen::Vector3d> out;
  if (!n) return out;
  if (!n.IsMap()) fail(path, "key '" + key + "' must be a map {id: [x, y, z]}");
  for (const auto& kv : n) {
    SensorId id;
    try {
      id = kv.first.as<SensorId>();
    } catch (const YAML::Exception&) {
      fail(path, "key '" + key + "': id '" + kv.first.Scalar() + "' is not an integer");
    }
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
  try {
    return YAML::Load(normalizeFlowMaps(ss.str()));
  } catch (const YAML::Exception& e) {
    fail(path, std::string("YAML syntax error: ") + e.what());
  }
}

std::vector<PairBias> readPairBiases(const YAML::Node& n, const std::string& path, const std::string& key) {
  std::vector<PairBias> out;
  if (!n) return out;
  if (!n.IsSequence()) fail(path, "key '" + key + "' must be a list of {ids: [a, b], gamma, beta, sigma}");
  int i = 0;
  for (const auto& e : n) {
    const std::string k = key + "[" + std::to_string(i++) + "]";
    const auto ids = e["ids"];
    if (!ids || !ids.IsSequence() || ids.size() != 2) fail(path, "key '" + k + ".ids' must be [a, b]");
    PairBias b;
    b.a = ids[0].as<SensorId>();
    b.b = ids[1].as<SensorId>();
    if (b.a == b.b) fail(path, "key '" + k + ".ids' names the same device twice");
    b.gamma_m = e["gamma"] ? num(e["gamma"], path, k + ".gamma") : 0.0;
    b.beta = e["beta"] ? num(e["beta"], path, k + ".beta") : 1.0;
    b.sigma_m = e["sigma"] ? num(e["sigma"], path, k + ".sigma") : 0.1;
    b.sigma_gamma_m = e["sigma_gamma"] ? num(e["sigma_gamma"], path, k + ".sigma_gamma") : 0.0;
    b.sigma_beta = e["sigma_beta"] ? num(e["sigma_beta"], path, k + ".sigma_beta") : 0.0;
    if (b.sigma_m <= 0.0) fail(path, "key '" + k + ".sigma' must be > 0 [m]");
    out.push_back(b);
  }
  return out;
}

void emitVec(YAML::Emitter& e, const Eigen::Vector3d& v) {
  e << YAML::Flow << YAML::BeginSeq << v.x() << v.y() << v.z() << YAML::EndSeq;
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
  std::filesystem::path p(path);
  if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write file");
  out << header << body << "\n";
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
  SystemSetup s;
  if (root["imu_id"]) s.imu_id = root["imu_id"].as<SensorId>();
  if (root["baro_id"]) s.baro_id = root["baro_id"].as<SensorId>();
  s.rel_tag_positions = idVecMap(root["rel_tag_positions"], path, "rel_tag_positions");
  s.abs_anchor_positions = idVecMap(root["abs_anchor_positions"], path, "abs_anchor_positions");
  if (const auto sig = root["abs_anchor_sigmas"]) {
    if (!sig.IsMap()) fail(path, "key 'abs_anchor_sigmas' must be a map {id: sigma_m}");
    for (const auto& kv : sig) {
      const SensorId id = kv.first.as<SensorId>();
      if (!s.abs_anchor_positions.count(id)) {
        fail(path, "key 'abs_anchor_sigmas." + std::to_string(id) + "' names an anchor missing in abs_anchor_positions");
      }
      const double v = num(kv.second, path, "abs_anchor_sigmas." + std::to_string(id));
      if (v < 0) fail(path, "key 'abs_anchor_sigmas." + std::to_string(id) + "' must be >= 0 [m]");
      s.abs_anchor_sigmas_m[id] = v;
    }
  }
  for (const auto& [id, p] : s.rel_tag_positions) {
    if (s.abs_anchor_positions.count(id)) fail(path, "id " + std::to_string(id) + " is both a tag and an anchor");
  }
  s.pair_biases = readPairBiases(root["pair_biases"], path, "pair_biases");
  if (const auto baro = root["baro"]) {
    if (baro["p_IP"]) s.baro_p_IP = vec3(baro["p_IP"], path, "baro.p_IP");
    const auto rp = baro["reference_pressure"];
    if (rp && !rp.IsNull()) s.baro_reference_pressure_pa = num(rp, path, "baro.reference_pressure");
  }
  if (const auto ip = root["initial_pose"]; ip && !ip.IsNull()) {
    InitialPose p;
    p.p_IinG = vec3(ip["p_IinG"], path, "initial_pose.p_IinG");
    p.yaw_deg = num(ip["yaw_deg"], path, "initial_pose.yaw_deg");
    p.sigma_p_m = num(ip["sigma_p"], path, "initial_pose.sigma_p");
    p.sigma_yaw_deg = num(ip["sigma_yaw_deg"], path, "initial_pose.sigma_yaw_deg");
    if (p.sigma_p_m <= 0 || p.sigma_yaw_deg <= 0) fail(path, "initial_pose sigmas must be > 0");
    s.initial_pose = p;
  }
  if (const auto n = root["noise"]; n && n.IsMap()) {
    auto opt = [&](const char* key, std::optional<double>& dst) {
      if (n[key] && !n[key].IsNull()) dst = num(n[key], path, std::string("noise.") + key);
    };
    opt("sigma_range", s.noise.sigma_range_m);
    opt("imu_acc_noise_density", s.noise.imu_acc_noise_density);
    opt("imu_gyro_noise_density", s.noise.imu_gyro_noise_density);
    opt("imu_acc_bias_rw", s.noise.imu_acc_bias_rw);
    opt("imu_gyro_bias_rw", s.noise.imu_gyro_bias_rw);
    opt("baro_pressure_sigma", s.noise.baro_pressure_sigma_pa);
  }
  return s;
}

void saveSetup(const SystemSetup& s, const std::string& path) {
  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "imu_id" << YAML::Value << s.imu_id;
  e << YAML::Key << "baro_id" << YAML::Value << s.baro_id;
  e << YAML::Key << "rel_tag_positions" << YAML::Comment("tag position in the IMU frame [m]") << YAML::Value
    << YAML::BeginMap;
  for (const auto& [id, p] : s.rel_tag_positions) {
    e << YAML::Key << id << YAML::Value;
    emitVec(e, p);
  }
  e << YAML::EndMap;
  e << YAML::Key << "abs_anchor_positions" << YAML::Comment("known anchors in the world frame [m]") << YAML::Value
    << YAML::BeginMap;
  for (const auto& [id, p] : s.abs_anchor_positions) {
    e << YAML::Key << id << YAML::Value;
    emitVec(e, p);
  }
  e << YAML::EndMap;
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
  const auto& n = s.noise;
  if (n.sigma_range_m || n.imu_acc_noise_density || n.imu_gyro_noise_density || n.imu_acc_bias_rw ||
      n.imu_gyro_bias_rw || n.baro_pressure_sigma_pa) {
    e << YAML::Key << "noise" << YAML::Value << YAML::BeginMap;
    auto put = [&](const char* k, const std::optional<double>& v, const char* unit) {
      if (v) e << YAML::Key << k << YAML::Value << *v << YAML::Comment(unit);
    };
    put("sigma_range", n.sigma_range_m, "m");
    put("imu_acc_noise_density", n.imu_acc_noise_density, "m/s^2/sqrt(Hz)");
    put("imu_gyro_noise_density", n.imu_gyro_noise_density, "rad/s/sqrt(Hz)");
    put("imu_acc_bias_rw", n.imu_acc_bias_rw, "m/s^3/sqrt(Hz)");
    put("imu_gyro_bias_rw", n.imu_gyro_bias_rw, "rad/s^2/sqrt(Hz)");
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
  e << YAML::Key << "anchor_positions" << YAML::Comment("all anchors, world frame [m]") << YAML::Value
    << YAML::BeginMap;
  for (const auto& [id, p] : t.anchor_positions) {
    e << YAML::Key << id << YAML::Value;
    emitVec(e, p);
  }
  e << YAML::EndMap;
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
