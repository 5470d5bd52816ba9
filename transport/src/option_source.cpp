#include "transport/option_source.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <stdexcept>

namespace meshnav::transport {
namespace {

std::string normalize(std::string k) {
  std::replace(k.begin(), k.end(), '_', '-');
  return k;
}

}  // namespace

OptionSource::OptionSource(const Cli& cli, const std::vector<std::string>& declared) : cli_(cli) {
  if (!cli.has("config")) return;
  config_path_ = cli.get("config");
  YAML::Node root;
  try {
    root = YAML::LoadFile(config_path_);
  } catch (const std::exception& e) {
    throw std::runtime_error(config_path_ + ": cannot read YAML: " + e.what());
  }
  if (root.IsNull()) return;
  if (!root.IsMap()) throw std::runtime_error(config_path_ + ": expected a map of option: value");
  for (const auto& kv : root) {
    const std::string key = normalize(kv.first.as<std::string>());
    if (std::find(declared.begin(), declared.end(), key) == declared.end() || key == "config")
      throw std::runtime_error(config_path_ + ": unknown option '" + kv.first.as<std::string>() + "'");
    if (!kv.second.IsScalar())
      throw std::runtime_error(config_path_ + ": option '" + key + "' must be a single value");
    config_[key] = kv.second.as<std::string>();
  }
}

bool OptionSource::has(const std::string& name) const { return cli_.has(name) || config_.count(name) > 0; }

std::string OptionSource::get(const std::string& name, const std::string& fallback) const {
  if (cli_.has(name)) return cli_.get(name);
  auto it = config_.find(name);
  return it == config_.end() ? fallback : it->second;
}

double OptionSource::getDouble(const std::string& name, double fallback) const {
  if (cli_.has(name) || !config_.count(name)) return cli_.getDouble(name, fallback);
  const std::string& v = config_.at(name);
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (end == v.c_str() || *end != '\0' || !std::isfinite(d))
    throw std::runtime_error(config_path_ + ": option '" + name + "' expects a finite number, got '" + v + "'");
  return d;
}

int64_t OptionSource::getInt(const std::string& name, int64_t fallback) const {
  if (cli_.has(name) || !config_.count(name)) return cli_.getInt(name, fallback);
  const std::string& v = config_.at(name);
  char* end = nullptr;
  errno = 0;
  const long long i = std::strtoll(v.c_str(), &end, 10);
  if (end == v.c_str() || *end != '\0' || errno == ERANGE)
    throw std::runtime_error(config_path_ + ": option '" + name + "' expects an integer, got '" + v + "'");
  return i;
}

bool OptionSource::flag(const std::string& name) const {
  if (cli_.has(name)) return true;
  auto it = config_.find(name);
  return it != config_.end() && (it->second == "true" || it->second == "1" || it->second == "yes");
}

}  // namespace meshnav::transport
