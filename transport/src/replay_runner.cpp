#include "transport/replay_runner.h"

#include <spdlog/spdlog.h>

#include <stdexcept>
#include <thread>

#include "transport/stop_signal.h"

namespace meshnav::transport {

const std::vector<std::string>& replayOptionNames() {
  static const std::vector<std::string> names = {"rate", "t0-utime", "data-t0", "wait-for",
                                                 "wait-timeout", "start-delay", "progress"};
  return names;
}

void declareReplayOptions(Cli& cli) {
  for (const auto& n : replayOptionNames()) cli.option(n);
}

ReplayProcessOptions replayOptionsFrom(const OptionSource& cli) {
  ReplayProcessOptions o;
  o.replay.rate = cli.getDouble("rate", 1.0);
  if (!(o.replay.rate >= 0.0)) throw std::runtime_error("--rate must be >= 0 (0 = as fast as possible)");
  if (cli.has("t0-utime")) o.replay.t0_wall_utime = cli.getInt("t0-utime", 0);
  if (cli.has("data-t0")) {
    if (!cli.has("t0-utime")) throw std::runtime_error("--data-t0 needs --t0-utime");
    o.replay.data_t0 = Timestamp::fromSec(cli.getDouble("data-t0", 0.0));
  }
  o.wait_for = cli.get("wait-for");
  o.wait_timeout = Duration::fromSec(cli.getDouble("wait-timeout", 0.0));
  o.start_delay = Duration::fromSec(cli.getDouble("start-delay", 0.0));
  o.replay.progress_period = Duration::fromSec(cli.getDouble("progress", 5.0));
  return o;
}

bool waitForStart(LcmNode& node, const ReplayProcessOptions& o) {
  if (!o.wait_for.empty()) {
    spdlog::info("{}: waiting for a message on {}{}", node.name(), o.wait_for,
                 o.wait_timeout.us > 0 ? fmt::format(" (at most {:.1f} s)", o.wait_timeout.sec()) : "");
    if (!node.waitForMessage(o.wait_for, o.wait_timeout)) {
      if (!node.stopRequested())
        spdlog::error("{}: nothing on {} within {:.1f} s", node.name(), o.wait_for, o.wait_timeout.sec());
      return false;
    }
    spdlog::info("{}: {} seen, starting", node.name(), o.wait_for);
  }
  if (o.start_delay.us > 0) {
    replay::SystemClock clock;
    const int64_t until = clock.nowUtime() + o.start_delay.us;
    while (!node.stopRequested() && clock.nowUtime() < until) clock.sleepUntil(until, 50000);
  }
  return !node.stopRequested();
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
