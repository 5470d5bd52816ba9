#include "estimator/node/checkpoint.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "common/anchor_init_io.h"
#include "common/yaml_options.h"

namespace meshnav::estimator {

namespace fs = std::filesystem;

namespace {
constexpr const char* kStateFile = "estimator_state.yaml";
constexpr const char* kAnchorsFile = "estimator_anchors.yaml";

void emitVec(YAML::Emitter& e, const char* key, const double* v, int n) {
  e << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (int i = 0; i < n; ++i) e << v[i];
  e << YAML::EndSeq;
}

/// A list of `n` finite numbers at `key` (q_ItoG, cov_imu: lengths YamlOptions has no type for).
std::vector<double> numbers(YamlOptions& y, const std::string& key, size_t n) {
  const YAML::Node v = y.take(key);
  if (!v || !v.IsSequence() || v.size() != n) y.fail(key, "must be a list of " + std::to_string(n) + " numbers");
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

void writeAtomically(const fs::path& target, const std::string& text) {
  const fs::path tmp = target.string() + ".tmp";
  {
    std::ofstream f(tmp);
    if (!f) throw std::runtime_error(tmp.string() + ": cannot write");
    f << text;
    if (!f) throw std::runtime_error(tmp.string() + ": write failed");
  }
  fs::rename(tmp, target);
}
}  // namespace

void writeCheckpoint(const EstimatorCheckpoint& c, const std::string& dir) {
  fs::create_directories(dir);
  YAML::Emitter e;
  e.SetDoublePrecision(17);
  e << YAML::BeginMap;
  e << YAML::Key << "t" << YAML::Value << c.t.sec();
  emitVec(e, "p_IinG", c.imu.p_IinG.data(), 3);
  emitVec(e, "v_IinG", c.imu.v_IinG.data(), 3);
  const double q[4] = {c.imu.q_ItoG.x(), c.imu.q_ItoG.y(), c.imu.q_ItoG.z(), c.imu.q_ItoG.w()};
  emitVec(e, "q_ItoG", q, 4);
  emitVec(e, "bias_gyro_rad_s", c.imu.bias_gyro_rad_s.data(), 3);
  emitVec(e, "bias_acc_m_s2", c.imu.bias_acc_m_s2.data(), 3);
  std::vector<double> cov;
  for (int i = 0; i < ImuErr::kDim; ++i)
    for (int j = 0; j < ImuErr::kDim; ++j) cov.push_back(c.cov_imu(i, j));
  emitVec(e, "cov_imu", cov.data(), static_cast<int>(cov.size()));
  e << YAML::Key << "landed" << YAML::Value << c.landed;
  e << YAML::Key << "baro_reference_pa" << YAML::Value;
  if (c.baro_reference_pa)
    e << *c.baro_reference_pa;
  else
    e << YAML::Null;
  e << YAML::Key << "baro_bias_m" << YAML::Value << c.baro_bias_m;
  e << YAML::Key << "baro_bias_var_m2" << YAML::Value << c.baro_bias_var_m2;
  e << YAML::EndMap;
  // Anchors first: a state file is only read together with the anchors written before it.
  writeAnchorInitsYaml(c.anchors, (fs::path(dir) / (std::string(kAnchorsFile) + ".tmp")).string());
  fs::rename(fs::path(dir) / (std::string(kAnchorsFile) + ".tmp"), fs::path(dir) / kAnchorsFile);
  writeAtomically(fs::path(dir) / kStateFile, std::string(e.c_str()) + "\n");
}

std::optional<EstimatorCheckpoint> readCheckpoint(const std::string& dir) {
  const fs::path state = fs::path(dir) / kStateFile, anchors = fs::path(dir) / kAnchorsFile;
  if (!fs::exists(state)) return std::nullopt;
  const std::string path = state.string();
  YamlOptions y(YamlOptions::loadFile(path), path);
  EstimatorCheckpoint c;
  double t_s = 0.0;
  y.require("t", t_s);
  c.t = Timestamp::fromSec(t_s);
  y.require("p_IinG", c.imu.p_IinG);
  y.require("v_IinG", c.imu.v_IinG);
  y.require("bias_gyro_rad_s", c.imu.bias_gyro_rad_s);
  y.require("bias_acc_m_s2", c.imu.bias_acc_m_s2);
  const auto q = numbers(y, "q_ItoG", 4);
  c.imu.q_ItoG = Eigen::Quaterniond(q[3], q[0], q[1], q[2]);
  if (std::abs(c.imu.q_ItoG.norm() - 1.0) > 1e-3) y.fail("q_ItoG", "is not a unit quaternion");
  c.imu.q_ItoG.normalize();
  const auto cov = numbers(y, "cov_imu", ImuErr::kDim * ImuErr::kDim);
  for (int i = 0; i < ImuErr::kDim; ++i)
    for (int j = 0; j < ImuErr::kDim; ++j) c.cov_imu(i, j) = cov[static_cast<size_t>(i * ImuErr::kDim + j)];
  c.cov_imu = 0.5 * (c.cov_imu + c.cov_imu.transpose());
  if (Eigen::LLT<ImuMatrix>(c.cov_imu).info() != Eigen::Success) y.fail("cov_imu", "is not positive definite");
  y.require("landed", c.landed);
  y.read("baro_reference_pa", c.baro_reference_pa);
  y.require("baro_bias_m", c.baro_bias_m);
  y.require("baro_bias_var_m2", c.baro_bias_var_m2);
  if (c.baro_bias_var_m2 <= 0.0) y.fail("baro_bias_var_m2", "must be > 0");
  y.rejectUnknown();
  if (fs::exists(anchors)) c.anchors = readAnchorInitsYaml(anchors.string());
  return c;
}

}  // namespace meshnav::estimator
