#include "eval/anchor_metrics.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "eval/pose_error.h"

namespace meshnav::eval {

AnchorMetrics computeAnchorMetrics(const std::vector<AnchorEstimate>& anchor_rows,
                                   const std::map<SensorId, Eigen::Vector3d>& truth_positions,
                                   const std::map<SensorId, Eigen::Vector3d>& known_positions,
                                   const std::map<SensorId, AnchorEstimate>& initial_override,
                                   Diagnostics& diag) {
  std::map<SensorId, std::vector<AnchorEstimate>> by_id;
  for (const auto& a : anchor_rows) by_id[a.id].push_back(a);
  for (const auto& [id, est] : initial_override)
    if (!by_id.count(id)) by_id[id].push_back(est);  // calibrated but never written by the filter

  AnchorMetrics m;
  double sum_init = 0.0, sum_final = 0.0;
  for (auto& [id, rows] : by_id) {
    std::stable_sort(rows.begin(), rows.end(),
                     [](const AnchorEstimate& a, const AnchorEstimate& b) { return a.t < b.t; });
    AnchorError e;
    e.id = id;
    e.known = known_positions.count(id) > 0;
    e.n_estimates = static_cast<int>(rows.size());
    e.initial = rows.front();
    e.final_est = rows.back();
    if (auto it = initial_override.find(id); it != initial_override.end()) e.initial = it->second;
    auto t = truth_positions.find(id);
    if (t == truth_positions.end()) {
      diag.report("eval:anchor_without_truth",
                  "anchor " + std::to_string(id) + " has estimates but no true position in truth.yaml");
    } else {
      e.has_truth = true;
      e.p_true = t->second;
      const Eigen::Vector3d d0 = e.p_true - e.initial.p_AinG;
      const Eigen::Vector3d d1 = e.p_true - e.final_est.p_AinG;
      e.initial_error_m = d0.norm();
      e.final_error_m = d1.norm();
      e.initial_nees = nees(d0, e.initial.cov_p_m2);
      e.final_nees = nees(d1, e.final_est.cov_p_m2);
      if (!e.known) {
        ++m.n_estimated;
        sum_init += e.initial_error_m;
        sum_final += e.final_error_m;
      }
    }
    m.anchors.push_back(e);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  m.mean_initial_error_m = m.n_estimated > 0 ? sum_init / m.n_estimated : nan;
  m.mean_final_error_m = m.n_estimated > 0 ? sum_final / m.n_estimated : nan;
  return m;
}

namespace {

std::vector<double> readNumbers(const YAML::Node& node, size_t n, const std::string& where) {
  if (!node || !node.IsSequence() || node.size() != n)
    throw std::runtime_error(where + ": expected a list of " + std::to_string(n) + " numbers");
  std::vector<double> v;
  for (const auto& x : node) {
    v.push_back(x.as<double>());
    if (!std::isfinite(v.back())) throw std::runtime_error(where + ": '" + x.Scalar() + "' is not a finite number");
  }
  return v;
}

}  // namespace

std::map<SensorId, AnchorEstimate> readCalibrationYaml(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const std::exception& ex) {
    throw std::runtime_error(path + ": cannot read calibration YAML: " + ex.what());
  }
  YAML::Node list = root;
  if (root.IsMap() && root["anchors"]) list = root["anchors"];
  if (!list.IsSequence()) throw std::runtime_error(path + ": expected a list of anchor entries (or key 'anchors')");
  std::map<SensorId, AnchorEstimate> out;
  int idx = 0;
  for (const auto& entry : list) {
    const std::string where = path + ": entry " + std::to_string(idx++);
    try {
      if (!entry["id"]) throw std::runtime_error(where + ": missing key 'id'");
      if (!entry["p_AinG"]) throw std::runtime_error(where + ": missing key 'p_AinG'");
      AnchorEstimate a;
      a.id = entry["id"].as<SensorId>();
      const auto p = readNumbers(entry["p_AinG"], 3, where + " key 'p_AinG'");
      a.p_AinG = Eigen::Vector3d(p[0], p[1], p[2]);
      if (entry["p_AinG_cov"]) {
        const auto c = readNumbers(entry["p_AinG_cov"], 9, where + " key 'p_AinG_cov'");
        for (int r = 0; r < 3; ++r)
          for (int k = 0; k < 3; ++k) a.cov_p_m2(r, k) = c[3 * r + k];
      }
      if (entry["t"]) a.t = Timestamp::fromSec(entry["t"].as<double>());
      out[a.id] = a;  // a later entry is a re-calibration (the logger appends every ANCHOR_INIT): it wins
    } catch (const YAML::Exception& ex) {
      throw std::runtime_error(where + ": " + ex.what());
    } catch (const std::out_of_range& ex) {
      throw std::runtime_error(where + ": key 't': " + ex.what());
    }
  }
  return out;
}

}  // namespace meshnav::eval
