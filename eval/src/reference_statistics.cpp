#include "eval/reference_statistics.h"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace meshnav::eval {

std::map<std::pair<SensorId, SensorId>, ReferencePairStats> readReferenceStatistics(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open reference statistics");
  // Split into documents at lines starting with "---"; the first (header) is skipped because the
  // toolbox writes it in a form YAML parsers reject.
  std::vector<std::pair<int, std::string>> docs;  // (first line number, text)
  std::string line;
  int line_no = 0;
  bool in_doc = false;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.rfind("---", 0) == 0) {
      docs.emplace_back(line_no, line.substr(3) + "\n");
      in_doc = true;
    } else if (in_doc) {
      docs.back().second += line + "\n";
    }
  }
  std::map<std::pair<SensorId, SensorId>, ReferencePairStats> out;
  for (const auto& [first_line, text] : docs) {
    const std::string where = path + ":" + std::to_string(first_line);
    YAML::Node doc;
    try {
      doc = YAML::Load(text);
    } catch (const YAML::Exception& ex) {
      throw std::runtime_error(where + ": malformed document: " + ex.what());
    }
    if (!doc.IsMap() || !doc["ID"]) throw std::runtime_error(where + ": document without key 'ID'");
    YAML::Node bias = doc["contant_bias_table"] ? doc["contant_bias_table"] : doc["constant_bias_table"];
    const YAML::Node noise = doc["noise_table"];
    if (!bias || !bias.IsMap()) throw std::runtime_error(where + ": missing key 'contant_bias_table'");
    if (!noise || !noise.IsMap()) throw std::runtime_error(where + ": missing key 'noise_table'");
    try {
      const SensorId id1 = doc["ID"].as<SensorId>();
      for (const auto& kv : bias) {
        const SensorId id2 = kv.first.as<SensorId>();
        ReferencePairStats s;
        s.bias_table_m = kv.second.as<double>();
        if (!noise[id2]) throw std::runtime_error(where + ": noise_table has no entry for " + std::to_string(id2));
        s.noise_m = noise[id2].as<double>();
        out[{id1, id2}] = s;
      }
    } catch (const YAML::Exception& ex) {
      throw std::runtime_error(where + ": " + ex.what());
    }
  }
  if (out.empty()) throw std::runtime_error(path + ": no per-pair statistics found");
  return out;
}

}  // namespace meshnav::eval
