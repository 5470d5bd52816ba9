#pragma once
/// @file process_options.h
/// @brief Options every LCM process has (DESIGN §3): `--lcm-url`, `--config`, `--help`, plus
/// `--log-level`. Use: declareProcessOptions(cli) before cli.parse(); append kProcessUsage to the
/// usage text.

#include <string>

#include "common/cli.h"

namespace meshnav::transport {

inline constexpr const char* kProcessUsage =
    "Common process options:\n"
    "  --lcm-url URL      LCM provider (default: $LCM_DEFAULT_URL, else udpm://239.255.76.67:7667?ttl=0)\n"
    "  --config FILE      YAML options of the process\n"
    "  --log-level LEVEL  trace|debug|info|warn|error (default: $MESHNAV_LOG_LEVEL, else info)\n"
    "  --help             this text\n"
    "SIGINT / SIGTERM stop the process cleanly.\n";

/// Declares --lcm-url, --config, --log-level on `cli`.
void declareProcessOptions(Cli& cli);
/// setupLogging(program) + --log-level + StopSignal::install().
void startProcess(const std::string& program, const Cli& cli);

}  // namespace meshnav::transport
