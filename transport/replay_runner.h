#pragma once
/// @file replay_runner.h
/// @brief What every replaying bridge does around ReplayScheduler: options (`--rate`,
/// `--t0-utime`, `--data-t0`, `--wait-for`, `--wait-timeout`, `--start-delay`, `--progress`,
/// `--drain`, `--drain-timeout`),
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
  /// After the last message: wait until ESTIMATOR_STATUS reports a filter time at or after the
  /// last IMU sample's stamp (the estimator has processed everything), at most `drain_timeout`.
  bool drain = false;
  Duration drain_timeout{Duration::fromSec(60.0)};
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
  bool drain = false;
  double drain_timeout_s = 60.0;
};

/// Declares --rate, --t0-utime, --data-t0, --wait-for, --wait-timeout, --start-delay, --progress
/// bound to `values` (which must outlive the parse).
void declareReplayOptions(Cli& cli, ReplayCliValues& values);
/// The options after parsing. Throws std::runtime_error on --data-t0 without --t0-utime.
ReplayProcessOptions replayOptionsFrom(const Cli& cli, const ReplayCliValues& values);

/// Waits for --wait-for / --start-delay. Returns false when stopped or timed out (logged).
bool waitForStart(LcmNode& node, const ReplayProcessOptions& options);

/// With `options.drain`: waits until this vehicle's ESTIMATOR_STATUS says the filter time reached
/// `last_t` (the data time of the last sample the estimator acts on at once, an IMU sample), so that
/// a launch stopped once the bridges have exited (`shutdown_after`) does not stop an estimator that
/// is still working through its queue (a 10× replay on a loaded machine). Returns true when it did
/// (or without `drain`), false on a stop request or after `drain_timeout` (logged as a warning).
bool waitForDrain(LcmNode& node, const ReplayProcessOptions& options, Timestamp last_t);

/// Paces `events` with the system clock, calling `emit` for each; stops on SIGINT/SIGTERM.
/// Logs the final progress line.
replay::ReplayProgress runReplay(const ReplayProcessOptions& options, const std::vector<replay::ReplayEvent>& events,
                                 const std::function<void(const replay::ReplayEvent&)>& emit);

}  // namespace meshnav::transport
