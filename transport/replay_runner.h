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
#include "transport/lcm_node.h"
#include "transport/replay/replay_scheduler.h"

namespace meshnav::transport {

struct ReplayProcessOptions {
  replay::ReplayOptions replay;
  std::string wait_for;                 ///< channel to see a message on before starting ("" = none)
  Duration wait_timeout{0};             ///< give up waiting after this (≤ 0: never)
  Duration start_delay{0};              ///< extra delay before the replay starts
};

/// The replay options as given on the command line (or in the `--config` options file).
struct ReplayCliValues {
  double rate = replay::ReplayOptions{}.rate;
  int64_t t0_utime = 0;
  double data_t0_s = 0.0;
  std::string wait_for;
  double wait_timeout_s = 0.0;
  double start_delay_s = 0.0;
  double progress_s = replay::ReplayOptions{}.progress_period.sec();
};

/// Declares --rate, --t0-utime, --data-t0, --wait-for, --wait-timeout, --start-delay, --progress
/// bound to `values` (which must outlive the parse).
void declareReplayOptions(Cli& cli, ReplayCliValues& values);
/// The options after parsing. Throws std::runtime_error on --data-t0 without --t0-utime.
ReplayProcessOptions replayOptionsFrom(const Cli& cli, const ReplayCliValues& values);

/// Waits for --wait-for / --start-delay. Returns false when stopped or timed out (logged).
bool waitForStart(LcmNode& node, const ReplayProcessOptions& options);

/// Paces `events` with the system clock, calling `emit` for each; stops on SIGINT/SIGTERM.
/// Logs the final progress line.
replay::ReplayProgress runReplay(const ReplayProcessOptions& options, const std::vector<replay::ReplayEvent>& events,
                                 const std::function<void(const replay::ReplayEvent&)>& emit);

}  // namespace meshnav::transport
