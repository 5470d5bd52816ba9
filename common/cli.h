#pragma once
/// @file cli.h
/// @brief Minimal command-line parser shared by every binary: `--key value`, `--flag`, `--help`.

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace meshnav {

class Cli {
 public:
  /// `usage` is printed by --help and on errors; it lists every option with units and defaults.
  Cli(std::string program, std::string usage);
  /// Declares an option taking a value (`--name VALUE`) or a flag (`--name`).
  Cli& option(const std::string& name, bool takes_value = true);
  /// Parses argv. Prints usage and returns false on --help (set `exit_code` 0) or on an unknown
  /// option / missing value (`exit_code` 2).
  bool parse(int argc, char** argv, int& exit_code);
  bool has(const std::string& name) const;
  std::string get(const std::string& name, const std::string& fallback = "") const;
  double getDouble(const std::string& name, double fallback) const;
  int64_t getInt(const std::string& name, int64_t fallback) const;
  const std::vector<std::string>& positional() const { return positional_; }
  const std::string& usage() const { return usage_; }

 private:
  std::string program_, usage_;
  std::map<std::string, bool> declared_;
  std::map<std::string, std::string> values_;
  std::vector<std::string> positional_;
};

/// Sets spdlog's pattern and level ("MESHNAV_LOG_LEVEL" env: trace|debug|info|warn|error).
void setupLogging(const std::string& program);

}  // namespace meshnav
