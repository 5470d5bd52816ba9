#include "estimator/restart/checkpoint.h"

#include "common/atomic_file.h"

#include <yaml-cpp/yaml.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "common/anchor_init_io.h"
#include "common/yaml_options.h"
#include "estimator/core/instance_kind.h"

namespace meshnav::estimator {

namespace fs = std::filesystem;

namespace {
constexpr const char* kStateFile = "estimator_state.yaml";
constexpr const char* kAnchorsFile = "estimator_anchors.yaml";
constexpr const char* kFormat = "meshnav_estimator_state";

void emitVec(YAML::Emitter& e, const char* key, const double* v, Eigen::Index n) {
  e << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (Eigen::Index i = 0; i < n; ++i) e << v[i];
  e << YAML::EndSeq;
}

void emitRecord(YAML::Emitter& e, const InstanceRecord& r) {
  e << YAML::BeginMap << YAML::Key << "kind" << YAML::Value << r.kind << YAML::Key << "id" << YAML::Value << r.id;
  if (!r.peers.empty()) e << YAML::Key << "peers" << YAML::Value << YAML::Flow << r.peers;
  emitVec(e, "value", r.value.data(), r.value.size());
  const Eigen::MatrixXd rowMajor = r.cov.transpose();  // column-major storage of the transpose
  emitVec(e, "cov", rowMajor.data(), rowMajor.size());
  e << YAML::EndMap;
}

/// A list of finite numbers at `key` (`n` of them unless n < 0).
std::vector<double> numbers(YamlOptions& y, const std::string& key, long n = -1) {
  const YAML::Node v = y.take(key);
  if (!v || !v.IsSequence() || (n >= 0 && static_cast<long>(v.size()) != n))
    y.fail(key, n >= 0 ? "must be a list of " + std::to_string(n) + " numbers" : "must be a list of numbers");
  std::vector<double> out;
  for (const auto& x : v) {
    double d = 0.0;
    try {
      d = x.as<double>();
    } catch (const YAML::Exception&) {
      y.fail(key, "holds '" + yamlText(x) + "', not a number");
    }
    if (!std::isfinite(d)) y.fail(key, "holds a non-finite value");
    out.push_back(d);
  }
  return out;
}

/// Instance `i` of the `instances` list: read, then checked against its kind.
InstanceRecord readRecord(const YAML::Node& node, const std::string& path, size_t i) {
  YamlOptions y(node, path, "instances[" + std::to_string(i) + "]");
  if (!node.IsMap()) y.fail("", "must be a map {kind, id, peers, value, cov}");
  InstanceRecord r;
  y.require("kind", r.kind);
  uint64_t id = 0;
  y.require("id", id);
  if (id > 0xffffffffULL) y.fail("id", "is not a 32-bit sensor id");
  r.id = static_cast<SensorId>(id);
  if (const YAML::Node peers = y.take("peers")) {
    if (!peers.IsSequence()) y.fail("peers", "must be a list of sensor ids");
    try {
      for (const auto& p : peers) r.peers.push_back(p.as<SensorId>());
    } catch (const YAML::Exception&) {
      y.fail("peers", "must be a list of sensor ids");
    }
  }
  const auto value = numbers(y, "value");
  r.value = Eigen::Map<const Eigen::VectorXd>(value.data(), static_cast<Eigen::Index>(value.size()));
  const auto cov = numbers(y, "cov");
  const auto n = static_cast<Eigen::Index>(std::lround(std::sqrt(static_cast<double>(cov.size()))));
  if (n * n != static_cast<Eigen::Index>(cov.size())) y.fail("cov", "must hold n×n numbers (row-major)");
  r.cov = Eigen::Map<const Eigen::MatrixXd>(cov.data(), n, n).transpose();
  r.cov = 0.5 * (r.cov + r.cov.transpose());
  y.rejectUnknown();
  try {
    checkInstanceRecord(r);
  } catch (const std::invalid_argument& e) {
    y.fail("kind", std::string("'") + r.kind + "' " + std::to_string(r.id) + ": " + e.what());
  }
  return r;
}

}  // namespace

void checkInstanceRecord(const InstanceRecord& r) {
  bool known = false;
  forEachKind([&]<class K>() {
    if (r.kind != K::kName) return;
    known = true;
    K::check(r.id, K::fromVector(r.value, r.peers), r.cov);
    if (Eigen::LLT<Eigen::MatrixXd>(r.cov).info() != Eigen::Success)
      throw std::invalid_argument("covariance is not positive definite");
  });
  if (!known) throw std::invalid_argument("not a registered kind (estimator/core/instance_kind.h)");
}

const InstanceRecord* EstimatorCheckpoint::find(const std::string& kind, SensorId id) const {
  for (const auto& r : instances)
    if (r.kind == kind && r.id == id) return &r;
  return nullptr;
}

void writeCheckpoint(const EstimatorCheckpoint& c, const std::string& dir, bool with_anchors) {
  fs::create_directories(dir);
  YAML::Emitter e;
  e.SetDoublePrecision(17);
  e << YAML::BeginMap;
  e << YAML::Key << "format" << YAML::Value << kFormat;
  e << YAML::Key << "version" << YAML::Value << EstimatorCheckpoint::kVersion;
  e << YAML::Key << "t" << YAML::Value << c.t.sec();
  e << YAML::Key << "landed" << YAML::Value << c.landed;
  e << YAML::Key << "baro_reference_pa" << YAML::Value;
  if (c.baro_reference_pa)
    e << *c.baro_reference_pa;
  else
    e << YAML::Null;
  e << YAML::Key << "instances" << YAML::Value << YAML::BeginSeq;
  emitRecord(e, {ImuKind::kName, c.imu_id, {}, ImuKind::toVector(c.imu), c.cov_imu});
  for (const auto& r : c.instances) emitRecord(e, r);
  e << YAML::EndSeq << YAML::EndMap;
  // Anchors first: a state file is only read together with the anchors written before it.
  if (with_anchors || !fs::exists(fs::path(dir) / kAnchorsFile)) {
    writeAnchorInitsYaml(c.anchors, (fs::path(dir) / (std::string(kAnchorsFile) + ".tmp")).string());
    fs::rename(fs::path(dir) / (std::string(kAnchorsFile) + ".tmp"), fs::path(dir) / kAnchorsFile);
  }
  writeFileAtomically((fs::path(dir) / kStateFile).string(), [&](std::ostream& out) { out << e.c_str() << "\n"; });
}

bool checkpointHasAnchorsFile(const std::string& dir) { return fs::exists(fs::path(dir) / kAnchorsFile); }

namespace {
/// `format` and `version` must say layout 2; a file of layout 1 (no `version`) is refused.
void requireVersion(YamlOptions& y) {
  if (!y.has("version"))
    throw std::runtime_error(y.file() + ": a checkpoint of layout 1 (no 'version' key, written before issue 11); this "
                             "estimator reads layout " + std::to_string(EstimatorCheckpoint::kVersion) +
                             " only: not used (remove the file, or let the estimator initialize anew)");
  std::string format;
  int version = 0;
  y.require("format", format);
  y.require("version", version);
  if (format != kFormat) y.fail("format", "must be '" + std::string(kFormat) + "', got '" + format + "'");
  if (version != EstimatorCheckpoint::kVersion)
    y.fail("version", "is " + std::to_string(version) + ", this estimator reads layout " +
                          std::to_string(EstimatorCheckpoint::kVersion) + " only");
}
}  // namespace

std::optional<EstimatorCheckpoint> readCheckpoint(const std::string& dir) {
  const fs::path state = fs::path(dir) / kStateFile, anchors = fs::path(dir) / kAnchorsFile;
  if (!fs::exists(state)) return std::nullopt;
  const std::string path = state.string();
  YamlOptions y(YamlOptions::loadFile(path), path);
  requireVersion(y);
  EstimatorCheckpoint c;
  double t_s = 0.0;
  y.require("t", t_s);
  c.t = Timestamp::fromSec(t_s);
  y.require("landed", c.landed);
  y.read("baro_reference_pa", c.baro_reference_pa);
  const YAML::Node list = y.take("instances");
  if (!list || !list.IsSequence() || list.size() == 0) y.fail("instances", "must be a list, the imu first");
  for (size_t i = 0; i < list.size(); ++i) {
    InstanceRecord r = readRecord(list[i], path, i);
    if ((i == 0) != (r.kind == ImuKind::kName))
      y.fail("instances[" + std::to_string(i) + "].kind", "the imu must be the first instance and the only one");
    if (i > 0 && c.find(r.kind, r.id)) y.fail("instances[" + std::to_string(i) + "].id", "is listed twice");
    if (i > 0) {
      c.instances.push_back(std::move(r));
      continue;
    }
    c.imu_id = r.id;
    c.imu = ImuKind::fromVector(r.value, r.peers);
    c.cov_imu = r.cov;
  }
  y.rejectUnknown();
  if (fs::exists(anchors)) c.anchors = readAnchorInitsYaml(anchors.string());
  return c;
}

}  // namespace meshnav::estimator
