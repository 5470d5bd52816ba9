#include "eval/range_dataset.h"

#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "common/dataset.h"
#include "common/setup.h"

namespace fs = std::filesystem;

namespace meshnav::eval {

std::map<SensorId, Eigen::Vector3d> readAbsAnchorPositions(const std::string& path) {
  YAML::Node root;
  try {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (size_t pos = text.find(":["); pos != std::string::npos; pos = text.find(":[", pos + 2))
      text.insert(pos + 1, " ");
    root = YAML::Load(text);
  } catch (const std::exception& ex) {
    throw std::runtime_error(path + ": " + ex.what());
  }
  const YAML::Node a = root["abs_anchor_positions"];
  if (!a || !a.IsMap()) throw std::runtime_error(path + ": missing key 'abs_anchor_positions'");
  std::map<SensorId, Eigen::Vector3d> out;
  try {
    for (const auto& kv : a) {
      if (!kv.second.IsSequence() || kv.second.size() != 3)
        throw std::runtime_error(path + ": abs_anchor_positions[" + kv.first.Scalar() + "] is not [x, y, z]");
      const Eigen::Vector3d p(kv.second[0].as<double>(), kv.second[1].as<double>(), kv.second[2].as<double>());
      if (!p.allFinite())
        throw std::runtime_error(path + ": abs_anchor_positions[" + kv.first.Scalar() + "] is not finite");
      if (!out.emplace(kv.first.as<SensorId>(), p).second)
        throw std::runtime_error(path + ": abs_anchor_positions[" + kv.first.Scalar() + "] is given twice");
    }
  } catch (const YAML::Exception& ex) {
    throw std::runtime_error(path + ": abs_anchor_positions: " + ex.what());
  }
  return out;
}

RangeEvaluationInput loadRangeEvaluationInput(const std::string& dir_str, Diagnostics& diag, double max_dt_s) {
  const fs::path dir(dir_str);
  if (!fs::is_directory(dir)) throw std::runtime_error(dir_str + ": not a directory");
  RangeEvaluationInput in;
  in.truth.setMaxDt(max_dt_s);
  auto note = [&](const std::string& m) {
    spdlog::warn("{}", m);
    in.notes.push_back(m);
  };

  if (fs::exists(dir / "ranges.csv")) {
    in.kind = "meshnav dataset";
    in.ranges = readRangesCsv((dir / "ranges.csv").string(), diag);
    if (!fs::exists(dir / "truth.yaml"))
      throw std::runtime_error((dir / "truth.yaml").string() +
                               " does not exist: no true anchor positions, so no true ranges");
    const Truth t = loadTruth((dir / "truth.yaml").string());
    in.truth_pairs = t.pair_biases;
    in.truth.setStaticPositions(t.anchor_positions);
    if (fs::exists(dir / "groundtruth.csv") && fs::exists(dir / "setup.yaml")) {
      const SystemSetup setup = loadSetup((dir / "setup.yaml").string());
      in.truth.setTrajectory(readTumCsv((dir / "groundtruth.csv").string(), diag), setup.rel_tag_positions);
    } else {
      note("no groundtruth.csv or setup.yaml in " + dir_str + ": only anchor-to-anchor ranges are evaluated");
    }
    return in;
  }

  in.kind = "recording";
  std::vector<fs::path> files, true_files;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.size() < 4 || n.substr(n.size() - 4) != ".csv") continue;
    if (n.rfind("true_ranges", 0) == 0) true_files.push_back(e.path());
    else if (n.find("ranges") != std::string::npos) files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  std::sort(true_files.begin(), true_files.end());
  if (files.empty()) throw std::runtime_error(dir_str + ": neither ranges.csv nor *ranges*.csv found");
  for (const auto& f : files) {
    auto v = readRangesCsv(f.string(), diag);
    spdlog::info("{}: {} valid ranges", f.filename().string(), v.size());
    in.ranges.insert(in.ranges.end(), v.begin(), v.end());
  }
  std::stable_sort(in.ranges.begin(), in.ranges.end(),
                   [](const RangeSample& a, const RangeSample& b) { return a.t < b.t; });
  std::vector<RangeSample> true_ranges;
  for (const auto& f : true_files) {
    auto v = readRangesCsv(f.string(), diag);
    true_ranges.insert(true_ranges.end(), v.begin(), v.end());
  }
  if (true_files.empty()) note("no true_ranges*.csv in " + dir_str + ": only anchor-to-anchor ranges are evaluated");
  in.truth.setTrueRangeSamples(true_ranges);
  const fs::path cfg = fs::exists(dir / "config.yaml") ? dir / "config.yaml" : dir / "setup.yaml";
  if (!fs::exists(cfg)) throw std::runtime_error(dir_str + ": no config.yaml or setup.yaml with abs_anchor_positions");
  in.truth.setStaticPositions(readAbsAnchorPositions(cfg.string()));
  return in;
}

}  // namespace meshnav::eval
