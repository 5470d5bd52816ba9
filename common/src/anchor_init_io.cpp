#include "common/anchor_init_io.h"

#include "common/atomic_file.h"

#include <yaml-cpp/yaml.h>

#include <Eigen/Cholesky>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace meshnav {

std::string anchorInitValueError(const AnchorInit& a) {
  if (a.id <= 0) return "anchor id " + std::to_string(a.id) + " is not > 0";
  if (!a.p_AinG.allFinite() || !a.cov_p_m2.allFinite() ||
      Eigen::LLT<Eigen::Matrix3d>(0.5 * (a.cov_p_m2 + a.cov_p_m2.transpose())).info() != Eigen::Success)
    return "anchor " + std::to_string(a.id) + " with invalid position or covariance";
  for (const auto& b : a.biases)
    if (!std::isfinite(b.gamma_m) || !std::isfinite(b.beta) || b.beta <= 0.0 || !std::isfinite(b.sigma_m) ||
        !std::isfinite(b.sigma_gamma_m) || b.sigma_gamma_m < 0.0)
      return "anchor " + std::to_string(a.id) + " with invalid pair bias";
  if (const std::string e = a.jointCovarianceError(); !e.empty()) return "anchor " + std::to_string(a.id) + ": " + e;
  if (!a.hasJointCovariance()) return "";
  // Positive definite where it is used: the position and the γ with σ_γ > 0 (the candidates for
  // states; a pair with σ_γ = 0 is an exact dictionary value with a zero row).
  std::vector<Eigen::Index> rows = {0, 1, 2};
  for (size_t i = 0; i < a.biases.size(); ++i)
    if (a.biases[i].sigma_gamma_m > 0.0) rows.push_back(3 + static_cast<Eigen::Index>(i));
  const Eigen::MatrixXd J = a.jointCovariance();
  Eigen::MatrixXd used(rows.size(), rows.size());
  for (size_t r = 0; r < rows.size(); ++r)
    for (size_t c = 0; c < rows.size(); ++c)
      used(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = J(rows[r], rows[c]);
  if (Eigen::LLT<Eigen::MatrixXd>(used).info() != Eigen::Success)
    return "anchor " + std::to_string(a.id) + ": joint covariance of position and gamma not positive definite";
  return "";
}

namespace {

template <typename T>
void seq(YAML::Emitter& e, const char* key, const std::vector<T>& v) {
  e << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (const auto& x : v) e << x;
  e << YAML::EndSeq;
}

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what);
}

std::vector<double> numbers(const YAML::Node& n, const std::string& path, const std::string& key, size_t expect) {
  if (!n || !n.IsSequence()) fail(path, "key '" + key + "' missing or not a list");
  if (expect > 0 && n.size() != expect)
    fail(path, "key '" + key + "' must have " + std::to_string(expect) + " values, has " + std::to_string(n.size()));
  std::vector<double> v;
  for (const auto& x : n) {
    try {
      v.push_back(x.as<double>());
    } catch (const std::exception&) {
      fail(path, "key '" + key + "' holds a non-number");
    }
    if (!std::isfinite(v.back())) fail(path, "key '" + key + "' holds a value that is not finite (" + x.Scalar() + ")");
  }
  return v;
}

/// Device ids: whole numbers in [0, INT32_MAX] (a cast of anything else to SensorId is undefined).
std::vector<SensorId> ids(const YAML::Node& n, const std::string& path, const std::string& key) {
  std::vector<SensorId> out;
  for (double x : numbers(n, path, key, 0)) {
    if (x != std::floor(x) || x < 0 || x > INT32_MAX)
      fail(path, "key '" + key + "' holds '" + std::to_string(x) + "', not a device id");
    out.push_back(static_cast<SensorId>(x));
  }
  return out;
}

}  // namespace

void writeAnchorInitsYaml(const std::vector<AnchorInit>& inits, const std::string& path,
                          const std::vector<RefusedAnchor>& refused) {
  YAML::Emitter e;
  e.SetDoublePrecision(15);
  e << YAML::BeginMap;
  e << YAML::Key << "anchors" << YAML::Value << YAML::BeginSeq;
  for (const auto& a : inits) {
    e << YAML::BeginMap;
    e << YAML::Key << "id" << YAML::Value << a.id;
    e << YAML::Key << "t" << YAML::Value << a.t.sec();
    seq(e, "p_AinG", std::vector<double>{a.p_AinG.x(), a.p_AinG.y(), a.p_AinG.z()});
    std::vector<double> cov;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) cov.push_back(a.cov_p_m2(i, j));
    seq(e, "p_AinG_cov", cov);
    std::vector<int> ids;
    std::vector<double> g, b, sg, sb, sr;
    for (const auto& pb : a.biases) {
      ids.push_back(pb.a == a.id ? pb.b : pb.a);
      g.push_back(pb.gamma_m);
      b.push_back(pb.beta);
      sg.push_back(pb.sigma_gamma_m);
      sb.push_back(pb.sigma_beta);
      sr.push_back(pb.sigma_m);
    }
    seq(e, "ref_ids", ids);
    seq(e, "const_biases", g);
    seq(e, "dist_biases", b);
    seq(e, "sigma_const_biases", sg);
    seq(e, "sigma_dist_biases", sb);
    seq(e, "sigma_ranges", sr);
    if (a.hasJointCovariance()) {
      std::vector<double> gp, gg;
      for (Eigen::Index i = 0; i < a.cov_gamma_p_m2.rows(); ++i)
        for (int j = 0; j < 3; ++j) gp.push_back(a.cov_gamma_p_m2(i, j));
      for (Eigen::Index i = 0; i < a.cov_gamma_m2.rows(); ++i)
        for (Eigen::Index j = 0; j < a.cov_gamma_m2.cols(); ++j) gg.push_back(a.cov_gamma_m2(i, j));
      seq(e, "cov_gamma_p", gp);
      seq(e, "cov_gamma", gg);
    }
    e << YAML::Key << "n_inliers" << YAML::Value << a.n_inliers;
    e << YAML::Key << "n_outliers" << YAML::Value << a.n_outliers;
    e << YAML::EndMap;
  }
  e << YAML::EndSeq;
  e << YAML::Key << "refused" << YAML::Value << YAML::BeginSeq;
  for (const auto& r : refused) {
    e << YAML::Flow << YAML::BeginMap << YAML::Key << "id" << YAML::Value << r.id << YAML::Key << "status"
      << YAML::Value << r.status << YAML::Key << "reason" << YAML::Value << r.reason << YAML::EndMap;
  }
  e << YAML::EndSeq << YAML::EndMap;
  writeFileAtomically(path, [&](std::ostream& out) { out << e.c_str() << "\n"; });
}

std::vector<AnchorInit> readAnchorInitsYaml(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const std::exception& ex) {
    fail(path, std::string("cannot read (") + ex.what() + ")");
  }
  const YAML::Node list = root.IsSequence() ? root : root["anchors"];
  if (!list || !list.IsSequence()) fail(path, "key 'anchors' missing or not a list");
  std::vector<AnchorInit> out;
  for (size_t k = 0; k < list.size(); ++k) {
    const YAML::Node n = list[k];
    const std::string pre = "anchors[" + std::to_string(k) + "].";
    AnchorInit a;
    try {
      if (!n["id"]) fail(path, "key '" + pre + "id' missing");
      a.id = n["id"].as<SensorId>();
      a.t = n["t"] ? Timestamp::fromSec(n["t"].as<double>()) : Timestamp{};
      a.n_inliers = n["n_inliers"] ? n["n_inliers"].as<int>() : 0;
      a.n_outliers = n["n_outliers"] ? n["n_outliers"].as<int>() : 0;
    } catch (const YAML::Exception& ex) {
      fail(path, "entry '" + pre + "' has a malformed scalar (" + ex.what() + ")");
    } catch (const std::out_of_range& ex) {
      fail(path, "key '" + pre + "t': " + ex.what());
    }
    const auto p = numbers(n["p_AinG"], path, pre + "p_AinG", 3);
    a.p_AinG = Eigen::Vector3d(p[0], p[1], p[2]);
    const auto c = numbers(n["p_AinG_cov"], path, pre + "p_AinG_cov", 9);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) a.cov_p_m2(i, j) = c[static_cast<size_t>(3 * i + j)];
    const auto refs = ids(n["ref_ids"], path, pre + "ref_ids");
    const size_t m = refs.size();
    const auto g = numbers(n["const_biases"], path, pre + "const_biases", m);
    const auto b = numbers(n["dist_biases"], path, pre + "dist_biases", m);
    const auto sg = numbers(n["sigma_const_biases"], path, pre + "sigma_const_biases", m);
    const auto sb = numbers(n["sigma_dist_biases"], path, pre + "sigma_dist_biases", m);
    const auto sr = n["sigma_ranges"] ? numbers(n["sigma_ranges"], path, pre + "sigma_ranges", m) : std::vector<double>(m, 0.1);
    for (size_t i = 0; i < m; ++i) {
      PairBias pbias;
      pbias.a = refs[i];
      pbias.b = a.id;
      pbias.gamma_m = g[i];
      pbias.beta = b[i];
      pbias.sigma_gamma_m = sg[i];
      pbias.sigma_beta = sb[i];
      pbias.sigma_m = sr[i];
      a.biases.push_back(pbias);
    }
    // Optional (issue 10): the joint covariance of p_AinG and the γ; both keys or neither.
    if (n["cov_gamma_p"] || n["cov_gamma"]) {
      const auto gp = numbers(n["cov_gamma_p"], path, pre + "cov_gamma_p", 3 * m);
      const auto gg = numbers(n["cov_gamma"], path, pre + "cov_gamma", m * m);
      const auto mm = static_cast<Eigen::Index>(m);
      a.cov_gamma_p_m2.resize(mm, 3);
      a.cov_gamma_m2.resize(mm, mm);
      for (Eigen::Index i = 0; i < mm; ++i) {
        for (int j = 0; j < 3; ++j) a.cov_gamma_p_m2(i, j) = gp[static_cast<size_t>(3 * i + j)];
        for (Eigen::Index j = 0; j < mm; ++j) a.cov_gamma_m2(i, j) = gg[static_cast<size_t>(mm * i + j)];
      }
    }
    out.push_back(std::move(a));
  }
  return out;
}

}  // namespace meshnav
