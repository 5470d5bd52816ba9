#pragma once
/// @file process_main.h
/// @brief The start-up every LCM process shares, so that a process main is its node's wiring
/// only: the command line (common/cli.h) with the options every process has (`--lcm-url`,
/// `--log-level`, `--channel-prefix`, `--help`), logging, SIGINT/SIGTERM (StopSignal), the LCM instance, exceptions
/// turned into a logged error and exit 1, and the heartbeat that publishes the node's status
/// stamped with the wall time and the process's own counters (malformed messages per channel).
///
/// Use:
///   transport::ProcessMain process("estimator", "Fuses ...");
///   process.cli().option("heartbeat", heartbeat_s, "...");
///   return process.run(argc, argv, [&] { ...; return process.lcm().spin(); });
/// or, with an options struct and its `declareOptions(Cli&, Options&)`:
///   return process.run<Options>(argc, argv, declareOptions, [&](Options& o) { ... });

#include <spdlog/spdlog.h>

#include <functional>
#include <map>
#include <memory>
#include <string>

#include "common/cli.h"
#include "transport/channels.h"
#include "transport/fleet_bus.h"
#include "transport/lcm_node.h"
#include "transport/replay/clock.h"

namespace meshnav::transport {

class ProcessMain {
 public:
  /// Declares --lcm-url, --log-level, --channel-prefix and --yield-cpu on cli(); the process adds
  /// its own options. `--yield-cpu`: a process whose latency does not matter (the fleet's
  /// calibrator and mission) runs below the others: under a real-time policy (`chrt -f N`, which
  /// every process of a launch inherits) one priority level lower, else niceness + 10; set before
  /// any LCM instance, so that LCM's receive threads inherit it. `--yield-rt` (a fleet's bridges):
  /// the real-time part only; under normal scheduling nothing (measured: niceness + 10 on the
  /// bridges held the estimators' answers back, p99 3–5 → 6–10 ms).
  /// `--channel-prefix P` (a vehicle of a fleet, docs/channels.md "Vehicle prefixes"): every typed
  /// channel of the process goes on the wire as channels::prefixed(channel, P); a malformed P is
  /// refused (exit 2) with the reason.
  ProcessMain(std::string name, const std::string& description);

  Cli& cli() { return cli_; }
  const std::string& name() const { return name_; }

  /// Exit status of a process that stopped because another instance of it already publishes its
  /// channels on the same LCM network (LcmNode::secondInstance), or holds its output folder
  /// (DirLockError, common/dir_lock.h): the supervisor does not respawn it.
  static constexpr int kExitSecondInstance = 7;

  /// Parses the command line (--help: exit 0; a bad one: exit 2), sets up logging (--log-level,
  /// else $MESHNAV_LOG_LEVEL) and the SIGINT/SIGTERM stop, and runs `body`, whose return value is
  /// the exit code; an exception out of it is logged and gives exit 1; kExitSecondInstance when
  /// the LCM node stopped as a second instance.
  int run(int argc, char** argv, const std::function<int()>& body);
  /// The same with the options held here: `declare(cli(), options)` before parsing, then
  /// `body(options)`.
  template <class Options>
  int run(int argc, char** argv, void (*declare)(Cli&, Options&), const std::function<int(Options&)>& body) {
    Options options;
    declare(cli_, options);
    return run(argc, argv, [&] { return body(options); });
  }
  /// Unless `given`, ends run() with exit 2 and "--<option> is required (see --help)": for an
  /// option the process cannot run without but --print-config can (so CLI11 may not require it).
  void require(bool given, const std::string& option) const;

  /// The vehicle prefix of --channel-prefix ("" when not given).
  const std::string& channelPrefix() const { return channel_prefix_; }
  /// The LCM instance on --lcm-url with --channel-prefix (created on first use; throws when LCM
  /// cannot start).
  LcmNode& lcm();
  /// --lcm-url as given ("" when not: resolveLcmUrl then takes the environment's).
  const std::string& lcmUrlOption() const { return lcm_url_; }
  /// Makes lcm() the instance on `url` with channel prefix `prefix` instead of --lcm-url and
  /// --channel-prefix: a process that serves several buses (the fleet's calibrator) names its
  /// first. Throws std::logic_error once lcm() was created.
  void useLcm(std::string url, std::string prefix);
  /// A process serving a fleet of `vehicles` (calibrator --fleet, mission --fleet): lcm() becomes
  /// the first vehicle's bus (vehicleLcmUrl(bus, --lcm-url or the environment's, 0); channel prefix
  /// `first_prefix`) and one more LCM instance, owned here, is opened per further bus. Returns each
  /// vehicle's bus (vehicles on one bus share its instance). Throws as useLcm and vehicleLcmUrl.
  std::vector<LcmNode*> fleetBuses(size_t vehicles, FleetBus bus, const std::string& first_prefix);

  /// `status` as published: stamped with the wall time, and with the process's own counters
  /// (added to `counters`, or appended to `text` for a status without counters).
  template <class Status>
  Status stamped(Status status) {
    status.wall_utime = replay::wallUtimeNow();
    if constexpr (requires { status.counters; }) {
      for (const auto& [k, v] : lcm().diagnostics().snapshot()) status.counters[k] += v;
    } else {
      if (lcm().diagnostics().total() > 0) status.text += "; counters: " + lcm().diagnostics().summary();
    }
    return status;
  }

  /// Publishes stamped(status()) on `channel` every `period_s` of wall time from spin() (first at
  /// once, so that others can wait for the process), then calls `after` with what was published.
  template <class Status>
  void heartbeat(channels::Channel<Status> channel, double period_s, std::type_identity_t<std::function<Status()>> status,
                 std::type_identity_t<std::function<void(const Status&)>> after = {}) {
    lcm().setHeartbeat(Duration::fromSec(period_s), [this, channel, status, after] {
      const Status st = stamped(status());
      lcm().publish(channel, st);
      if (after) after(st);
    });
  }

 private:
  std::string name_;
  Cli cli_;
  std::string lcm_url_;
  std::string log_level_;
  std::string channel_prefix_;
  bool yield_cpu_ = false;  ///< --yield-cpu
  bool yield_rt_ = false;   ///< --yield-rt
  std::vector<std::unique_ptr<LcmNode>> fleet_buses_;  ///< fleetBuses() beyond lcm()
  std::unique_ptr<LcmNode> lcm_;
};

/// "key=value key=value " of a counter map, for the last log line of a process.
std::string formatCounters(const std::map<std::string, int64_t>& counters);

}  // namespace meshnav::transport
