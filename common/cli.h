#pragma once
/// @file cli.h
/// @brief The command line of every meshnav binary, on CLI11 (libcli11-dev): each option is
/// declared once, bound to the variable that holds its value, and `--help` is built from those
/// declarations, with the default taken from the variable's initial value (the code), so the text
/// cannot drift from the behaviour. Values are converted and range-checked while parsing: a
/// number that does not fit its type (an id of 4294967297 into 32 bits), a NaN where a finite
/// value is needed, or an unknown option is refused with a message naming the option, exit 2.
///
/// Use:
///   Cli cli("estimator", "Fuses IMU, BARO, RANGE ... (one paragraph)");
///   double heartbeat_s = 1.0;
///   cli.option("heartbeat", heartbeat_s, "wall seconds between heartbeat statuses")->check(cli::positive());
///   int code = 0;
///   if (!cli.parse(argc, argv, code)) return code;  // --help: 0, bad command line: 2

#include <CLI/CLI.hpp>

#include <functional>
#include <string>
#include <vector>

namespace meshnav {

class Cli {
 public:
  /// `description` is the paragraph --help prints above the options.
  Cli(std::string program, const std::string& description);
  Cli(const Cli&) = delete;
  Cli& operator=(const Cli&) = delete;

  CLI::App& app() { return app_; }
  const std::string& program() const { return program_; }

  /// `--name VALUE` bound to `value`; --help shows the value it holds now as the default.
  template <class T>
  CLI::Option* option(const std::string& name, T& value, const std::string& help) {
    return app_.add_option("--" + name, value, help)->capture_default_str();
  }
  /// `--name VALUE` bound to `value`, no default shown (the help text says what happens without it).
  template <class T>
  CLI::Option* optional(const std::string& name, T& value, const std::string& help) {
    return app_.add_option("--" + name, value, help);
  }
  /// `--name` (no value) sets `value` to true.
  CLI::Option* flag(const std::string& name, bool& value, const std::string& help);
  /// Comma-separated non-negative 32-bit ids (`--anchors 106,107`); an id out of range is refused.
  CLI::Option* idList(const std::string& name, std::vector<int32_t>& ids, const std::string& help);

  /// `--fleet FILE` (help `fleet_help`) and `--bus per-vehicle|shared` of a process that serves a
  /// fleet over LCM (calibrator, mission; docs/fleet.md); --fleet excludes --channel-prefix when
  /// that is declared (transport::ProcessMain declares it first). Returns the --fleet option.
  CLI::Option* fleetServing(std::string& fleet_path, std::string& bus, const std::string& fleet_help);

  /// `--config FILE`: a flat YAML map of this command's options (`rate: 10`, `wait_for:
  /// ESTIMATOR_STATUS`; `_` and `-` are the same). The command line wins over the file; a key that
  /// is not an option, or not a single value, is refused naming the file and the key.
  CLI::Option* optionsFile(const std::string& help);

  /// True when `--name` was given (on the command line or in the options file).
  bool given(const std::string& name) const;

  /// Parses argv. Returns false on --help (text on stdout, `exit_code` 0) or on a bad command line
  /// (message naming the option on stderr and in error(), `exit_code` 2).
  bool parse(int argc, char** argv, int& exit_code);
  /// The same for arguments without the program name (tests).
  bool parse(const std::vector<std::string>& args, int& exit_code);
  /// The message of the last refused command line ("" after a good one).
  const std::string& error() const { return error_; }
  std::string help() const { return app_.help(); }

 private:
  bool handle(const std::function<void()>& parse_call, int& exit_code);

  std::string program_;
  CLI::App app_;
  CLI::Option* options_file_ = nullptr;
  std::function<std::string(const std::string&)> spelled_;  ///< an options-file key as written
  std::string error_;
};

/// Value checks for Cli options (CLI11 validators); each refuses NaN and ±inf.
namespace cli {
CLI::Validator finite();       ///< a finite number
CLI::Validator nonNegative();  ///< a finite number >= 0
CLI::Validator positive();     ///< a finite number > 0
/// A name accepted by `accepts` (e.g. estimator::strategyListed); `names` lists them for --help.
CLI::Validator oneOf(std::function<bool(const std::string&)> accepts, const std::string& names);
}  // namespace cli

/// Sets spdlog's pattern and level ("MESHNAV_LOG_LEVEL" env: trace|debug|info|warn|error).
void setupLogging(const std::string& program);

}  // namespace meshnav
