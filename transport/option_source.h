#pragma once
/// @file option_source.h
/// @brief Process options from the command line, falling back to the `--config` YAML file: a flat
/// map whose keys are the long option names (`rate: 10`, `wait-for: ESTIMATOR_STATUS`; `_` and `-`
/// are interchangeable). The command line wins. Unknown keys in the file are reported as errors, so
/// a typo does not silently fall back to a default.

#include <map>
#include <string>

#include "common/cli.h"

namespace meshnav::transport {

class OptionSource {
 public:
  /// Reads `--config` when given. Throws std::runtime_error naming the file and key when the file
  /// is not a flat map, or has a key that `cli` does not declare (`declared` lists the names).
  OptionSource(const Cli& cli, const std::vector<std::string>& declared);

  bool has(const std::string& name) const;
  std::string get(const std::string& name, const std::string& fallback = "") const;
  double getDouble(const std::string& name, double fallback) const;
  int64_t getInt(const std::string& name, int64_t fallback) const;
  bool flag(const std::string& name) const;  ///< a flag given on the command line or `name: true`

 private:
  const Cli& cli_;
  std::string config_path_;
  std::map<std::string, std::string> config_;
};

}  // namespace meshnav::transport
