#include "transport/replay_runner.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <stdexcept>
#include <thread>

#include "meshnav/estimator_status_t.hpp"
#include "transport/channels.h"
#include "transport/stop_signal.h"

namespace meshnav::transport {

void declareReplayOptions(Cli& cli, ReplayCliValues& v) {
  cli.option("rate", v.rate, "playback speed: 1 = real time, N = N times faster, 0 = as fast as possible")
      ->type_name("N")
      ->check(cli::nonNegative());
  cli.optional("t0-utime", v.t0_utime,
               "wall time [µs since the Unix epoch] at which data time --data-t0 is played; give the same value "
               "to several bridges to replay them in step (default: at start)")
      ->type_name("US");
  cli.optional("data-t0", v.data_t0_s, "data time [s] played at --t0-utime (default 0; with --t0-utime only)")
      ->type_name("S")
      ->check(cli::finite());
  cli.optional("wait-for", v.wait_for, "start only after a message was seen on channel CH (e.g. ESTIMATOR_STATUS)")
      ->type_name("CH");
  cli.optional("wait-timeout", v.wait_timeout_s,
               "give up (exit 3) when nothing arrived on --wait-for within S seconds (default: wait forever)")
      ->type_name("S")
      ->check(cli::nonNegative());
  cli.option("start-delay", v.start_delay_s, "sleep S seconds before starting (prefer --wait-for)")
      ->type_name("S")
      ->check(cli::nonNegative());
  cli.option("progress", v.progress_s, "seconds between progress lines (0 = none)")
      ->type_name("S")
      ->check(cli::nonNegative());
  cli.flag("drain", v.drain,
           "after the last message, wait until ESTIMATOR_STATUS reports a filter time at or after the last IMU "
           "sample's (the estimator has caught up) before exiting");
  cli.option("drain-timeout", v.drain_timeout_s, "give up waiting with --drain after S wall seconds (a warning, exit 0)")
      ->type_name("S")
      ->check(cli::nonNegative());
}

ReplayProcessOptions replayOptionsFrom(const Cli& cli, const ReplayCliValues& v) {
  ReplayProcessOptions o;
  o.replay.rate = v.rate;
  if (cli.given("t0-utime")) o.replay.t0_wall_utime = v.t0_utime;
  if (cli.given("data-t0")) {
    if (!cli.given("t0-utime")) throw std::runtime_error("--data-t0 needs --t0-utime");
    o.replay.data_t0 = Timestamp::fromSec(v.data_t0_s);
  }
  o.wait_for = v.wait_for;
  o.wait_timeout = Duration::fromSec(v.wait_timeout_s);
  o.start_delay = Duration::fromSec(v.start_delay_s);
  o.replay.progress_period = Duration::fromSec(v.progress_s);
  o.drain = v.drain;
  o.drain_timeout = Duration::fromSec(v.drain_timeout_s);
  return o;
}

bool waitForStart(LcmNode& node, const ReplayProcessOptions& o) {
  if (!o.wait_for.empty()) {
    const std::string wire = channels::prefixedName(o.wait_for, node.channelPrefix());  // this vehicle's
    spdlog::info("{}: waiting for a message on {}{}", node.name(), wire,
                 o.wait_timeout.us > 0 ? fmt::format(" (at most {:.1f} s)", o.wait_timeout.sec()) : "");
    if (!node.waitForMessage(o.wait_for, o.wait_timeout)) {
      if (!node.stopRequested())
        spdlog::error("{}: nothing on {} within {:.1f} s", node.name(), wire, o.wait_timeout.sec());
      return false;
    }
    spdlog::info("{}: {} seen, starting", node.name(), wire);
  }
  if (o.start_delay.us > 0) {
    replay::SystemClock clock;
    const int64_t until = clock.nowUtime() + o.start_delay.us;
    while (!node.stopRequested() && clock.nowUtime() < until) clock.sleepUntil(until, 50000);
  }
  return !node.stopRequested();
}

bool waitForDrain(LcmNode& node, const ReplayProcessOptions& o, Timestamp last_t) {
  if (!o.drain) return true;
  const std::string wire = channels::prefixedName(channels::kEstimatorStatus.name, node.channelPrefix());
  int64_t newest_us = 0;
  const bool caught_up = node.waitForMessage(
      channels::kEstimatorStatus.name, o.drain_timeout, [&](const void* data, size_t size) {
        estimator_status_t m;
        if (m.decode(data, 0, static_cast<int>(size)) < 0) return false;  // counted by the estimator's own readers
        newest_us = std::max(newest_us, m.utime);
        return m.utime >= last_t.us;
      });
  if (caught_up) {
    spdlog::info("{}: {} reports the filter at t={}: the estimator has caught up", node.name(), wire, formatSeconds(last_t));
  } else if (!node.stopRequested()) {
    spdlog::warn("{}: {} did not reach t={} within {:g} s (newest filter time seen: {}): the estimator is behind or "
                 "dropped data; exiting anyway",
                 node.name(), wire, formatSeconds(last_t), o.drain_timeout.sec(),
                 newest_us > 0 ? formatSeconds(Timestamp{newest_us}) : std::string("none"));
  }
  return caught_up;
}

replay::ReplayProgress runReplay(const ReplayProcessOptions& o, const std::vector<replay::ReplayEvent>& events,
                                 const std::function<void(const replay::ReplayEvent&)>& emit) {
  replay::SystemClock clock;
  replay::ReplayScheduler scheduler(o.replay, clock);
  const auto p = scheduler.run(events, emit, [] { return StopSignal::requested(); });
  spdlog::info("{}{}", replay::ReplayScheduler::formatProgress(p, o.replay.rate), p.stopped ? " (stopped)" : " (done)");
  return p;
}

}  // namespace meshnav::transport
