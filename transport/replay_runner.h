#pragma once
/// @file replay_runner.h
/// @brief What every replaying bridge does around ReplayScheduler: options (`--rate`,
/// `--t0-utime`, `--data-t0`, `--wait-for`, `--wait-timeout`, `--start-delay`, `--progress`),
/// waiting for subscribers (a heartbeat on a channel, so tests wait on a condition), pacing, and
/// stopping on SIGINT/SIGTERM.

#include <functional>
#include <string>
#include <vector>

#include "common/cli.h"
#include "transport/option_source.h"
#include "transport/lcm_node.h"
#include "transport/replay/replay_scheduler.h"

namespace meshnav::transport {

struct ReplayProcessOptions {
  replay::ReplayOptions replay;
  std::string wait_for;                 ///< channel to see a message on before starting ("" = none)
  Duration wait_timeout{0};             ///< give up waiting after this (≤ 0: never)
  Duration start_delay{0};              ///< extra delay before the replay starts
};

inline constexpr const char* kReplayUsage =
    "Replay options:\n"
    "  --rate N           playback speed: 1 = real time (default), N = N times faster, 0 = as fast as possible\n"
    "  --t0-utime US      wall time [µs since the Unix epoch] at which data time --data-t0 is played;\n"
    "                     give the same value to several bridges to replay them in step (default: at start)\n"
    "  --data-t0 S        data time [s] played at --t0-utime (default 0; with --t0-utime only)\n"
    "  --wait-for CH      start only after a message was seen on channel CH (e.g. ESTIMATOR_STATUS)\n"
    "  --wait-timeout S   give up (exit 3) when nothing arrived on --wait-for within S seconds (default: wait forever)\n"
    "  --start-delay S    sleep S seconds before starting (prefer --wait-for)\n"
    "  --progress S       seconds between progress lines (default 5; 0 = none)\n";

/// Names of the replay options (for OptionSource).
const std::vector<std::string>& replayOptionNames();
void declareReplayOptions(Cli& cli);
/// Throws std::runtime_error on an invalid value.
ReplayProcessOptions replayOptionsFrom(const OptionSource& opts);

/// Waits for --wait-for / --start-delay. Returns false when stopped or timed out (logged).
bool waitForStart(LcmNode& node, const ReplayProcessOptions& options);

/// Paces `events` with the system clock, calling `emit` for each; stops on SIGINT/SIGTERM.
/// Logs the final progress line.
replay::ReplayProgress runReplay(const ReplayProcessOptions& options, const std::vector<replay::ReplayEvent>& events,
                                 const std::function<void(const replay::ReplayEvent&)>& emit);

}  // namespace meshnav::transport
