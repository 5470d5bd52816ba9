#include "transport/process_main.h"

#include <fmt/format.h>

#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "common/dir_lock.h"
#include "transport/stop_signal.h"

namespace meshnav::transport {

ProcessMain::ProcessMain(std::string name, const std::string& description)
    : name_(std::move(name)), cli_(name_, description + "\nSIGINT / SIGTERM stop the process cleanly. Exit 7: another instance of it already "
                                              "publishes its channels on this LCM network (it yields to it).") {
  cli_.optional("lcm-url", lcm_url_, "LCM provider (default: $LCM_DEFAULT_URL, else udpm://239.255.76.67:7667?ttl=0)")
      ->type_name("URL");
  cli_.optional("log-level", log_level_, "log level (default: $MESHNAV_LOG_LEVEL, else info)")
      ->type_name("LEVEL")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "warning", "error", "critical", "off"}));
  cli_.optional("channel-prefix", channel_prefix_,
                "vehicle prefix of this process's channels in a fleet: P/IMU, P/RANGE, P/POSE, ... (the fleet's "
                "shared CALIB_CMD, CALIB_STATUS, MISSION_STATUS stay unprefixed; docs/channels.md); 1-64 letters, "
                "digits, '_' or '-', e.g. a vehicle name of the fleet file (default: none)")
      ->type_name("P")
      ->check(CLI::Validator(
          [](std::string& p) { return channels::prefixProblem(p); },
          "", "vehicle prefix"));
  CLI::Option* yield = cli_.flag("yield-cpu", yield_cpu_,
            "run below the other processes (a calibrator, a mission: work whose latency does not matter): under a "
            "real-time policy (chrt) one priority level lower, else niceness + 10");
  CLI::Option* yield_rt = cli_.flag("yield-rt", yield_rt_,
            "under a real-time policy (chrt) one priority level lower, so that the estimators answer first (a fleet's "
            "bridges); else nothing: a niceness would hold back the data it carries (docs/fleet.md \"Who answers "
            "first\")");
  yield_rt->excludes(yield);
}

namespace {
/// --yield-cpu: one real-time priority level below the inherited one, or (`nice_otherwise`)
/// niceness + 10; --yield-rt: the former only. `flag` names the option in the log.
void yieldCpu(bool nice_otherwise, const char* flag) {
  const int policy = sched_getscheduler(0);
  sched_param param{};
  if ((policy == SCHED_FIFO || policy == SCHED_RR) && sched_getparam(0, &param) == 0) {
    const int lowest = sched_get_priority_min(policy);
    if (param.sched_priority > lowest) {
      --param.sched_priority;
      if (sched_setscheduler(0, policy, &param) == 0) {
        spdlog::info("{}: real-time priority {} ({})", flag, param.sched_priority, policy == SCHED_FIFO ? "FIFO" : "RR");
        return;
      }
    } else {
      // Already at the lowest real-time level: the normal policy is below every real-time one.
      param.sched_priority = 0;
      if (sched_setscheduler(0, SCHED_OTHER, &param) == 0) {
        spdlog::info("{}: normal scheduling (below every real-time process)", flag);
        return;
      }
    }
    spdlog::warn("{}: could not lower the real-time priority ({})", flag, std::strerror(errno));
    return;
  }
  if (!nice_otherwise) {
    spdlog::info("{}: no real-time policy, scheduling left as it is", flag);
    return;
  }
  errno = 0;
  if (nice(10) == -1 && errno != 0) spdlog::warn("{}: nice failed ({})", flag, std::strerror(errno));
  else spdlog::info("{}: niceness + 10", flag);
}
}  // namespace

namespace {
/// A required option missing (ProcessMain::require): exit 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
}  // namespace

void ProcessMain::require(bool given, const std::string& option) const {
  if (!given) throw UsageError("--" + option + " is required (see --help)");
}

int ProcessMain::run(int argc, char** argv, const std::function<int()>& body) {
  int code = 0;
  if (!cli_.parse(argc, argv, code)) return code;
  setupLogging(name_);
  if (!log_level_.empty()) spdlog::set_level(spdlog::level::from_str(log_level_));
  StopSignal::install();
  if (yield_cpu_ || yield_rt_) yieldCpu(yield_cpu_, yield_cpu_ ? "--yield-cpu" : "--yield-rt");
  try {
    const int rc = body();
    if (lcm_ && !lcm_->handlerTimes().empty()) spdlog::info("time in handlers: {}", lcm_->handlerTimeSummary());
    if (lcm_ && !lcm_->secondInstance().empty()) {
      spdlog::error("refused to run beside another instance (exit {})", kExitSecondInstance);
      return kExitSecondInstance;
    }
    return rc;
  } catch (const DirLockError& e) {
    spdlog::error("{}", e.what());
    return kExitSecondInstance;
  } catch (const UsageError& e) {
    spdlog::error("{}", e.what());
    return 2;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}

void ProcessMain::useLcm(std::string url, std::string prefix) {
  if (lcm_) throw std::logic_error("ProcessMain::useLcm after the LCM instance was created");
  lcm_url_ = std::move(url);
  channel_prefix_ = std::move(prefix);
}

std::vector<LcmNode*> ProcessMain::fleetBuses(size_t vehicles, FleetBus bus, const std::string& first_prefix) {
  const std::string base = resolveLcmUrl(lcm_url_);
  std::vector<std::string> urls;
  for (size_t k = 0; k < vehicles; ++k) urls.push_back(vehicleLcmUrl(bus, base, k));
  std::vector<LcmNode*> out;
  if (urls.empty()) return out;
  useLcm(urls[0], first_prefix);
  for (size_t k = 0; k < urls.size(); ++k) {
    const auto same = std::find(urls.begin(), urls.begin() + static_cast<std::ptrdiff_t>(k), urls[k]);
    if (k == 0) {
      out.push_back(&lcm());
    } else if (same != urls.begin() + static_cast<std::ptrdiff_t>(k)) {
      out.push_back(out[static_cast<size_t>(same - urls.begin())]);
    } else {
      fleet_buses_.push_back(std::make_unique<LcmNode>(name_, urls[k]));
      out.push_back(fleet_buses_.back().get());
    }
  }
  return out;
}

LcmNode& ProcessMain::lcm() {
  if (!lcm_) lcm_ = std::make_unique<LcmNode>(name_, lcm_url_, channel_prefix_);
  return *lcm_;
}

std::string formatCounters(const std::map<std::string, int64_t>& counters) {
  std::string out;
  for (const auto& [k, v] : counters) out += fmt::format("{}={} ", k, v);
  return out;
}

}  // namespace meshnav::transport
