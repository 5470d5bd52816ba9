#include "mission/process/mission_process_config.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace meshnav::mission {

const char* const kMissionProcessDescription =
    "Runs a mission script (mission/README.md) in data time: subscribes POSE, RANGE (data time; see --time-from), "
    "CALIB_STATUS, ESTIMATOR_STATUS; publishes CALIB_CMD, ESTIMATOR_CMD and MISSION_STATUS (also a wall-clock "
    "heartbeat). Step times are seconds after t0. Exits once every step ran and the calibrator answered the last "
    "Calibrate (or --linger passed), unless --stay.";

void declareMissionProcessOptions(Cli& cli, MissionProcessConfig& c) {
  cli.optional("mission", c.mission_path, "mission script (e.g. config/missions/paper_s2.yaml); required")
      ->type_name("FILE");
  cli.option("t0", c.t0_text,
             "dataset time [s] of step time 0 (e.g. 0 for meshnav_sim datasets); auto: the first data time "
             "received (start the mission before the data flows)")
      ->type_name("S|auto");
  cli.option("time-from", c.time_from_text,
             "comma-separated channels whose message time advances the mission clock, besides POSE (which starts "
             "only once the estimator initialized): RANGE, IMU, BARO, FLIGHT_STATE, or none")
      ->type_name("LIST");
  cli.flag("stay", c.stay, "keep running (heartbeat) after the mission finished");
  cli.option("linger", c.linger_s, "wall seconds to wait for the calibrator's answer to the last step before exiting")
      ->type_name("S")
      ->check(cli::nonNegative());
  cli.option("status-period", c.status_period_s, "MISSION_STATUS period in data time [s]")
      ->type_name("S")
      ->check(cli::positive());
  cli.option("resend-period", c.resend_period_s,
             "data seconds after which a CALIB_CMD whose effect no CALIB_STATUS shows yet is sent again (a lossy "
             "link; at most 30 times; 0 = never; keep it above the calibrator's CALIB_STATUS period, 1 s, which may be "
             "what carries the answer)")
      ->type_name("S")
      ->check(cli::nonNegative());
  cli.option("heartbeat", c.heartbeat_s, "wall seconds between heartbeat MISSION_STATUS")
      ->type_name("S")
      ->check(cli::positive());
  cli.fleetServing(c.fleet_path, c.bus,
                   "the fleet's mission: follow the first vehicle of this fleet file (its P/POSE, P/RANGE, "
                   "P/ESTIMATOR_STATUS on its bus) and send ESTIMATOR_CMD to every vehicle (P/ESTIMATOR_CMD on its "
                   "bus); CALIB_CMD, CALIB_STATUS, MISSION_STATUS on the first vehicle's bus, as calibrator --fleet");
  cli.flag("print-config", c.print_config, "print the options and exit");
}

namespace {

std::vector<std::string> splitChannels(const std::string& list) {
  std::vector<std::string> out;
  if (list == "none" || list.empty()) return out;
  std::stringstream ss(list);
  std::string item;
  while (std::getline(ss, item, ',')) {
    item.erase(0, item.find_first_not_of(" \t"));
    item.erase(item.find_last_not_of(" \t") + 1);
    if (item.empty()) continue;
    if (std::find(kTimeChannels.begin(), kTimeChannels.end(), item) == kTimeChannels.end())
      throw std::runtime_error("--time-from: unknown channel '" + item + "' (RANGE, IMU, BARO, FLIGHT_STATE or none)");
    if (std::find(out.begin(), out.end(), item) == out.end()) out.push_back(item);
  }
  return out;
}

}  // namespace

void finishMissionProcessConfig(MissionProcessConfig& c) {
  c.t0_s.reset();
  if (c.t0_text != "auto") {
    char* end = nullptr;
    const double v = std::strtod(c.t0_text.c_str(), &end);
    if (c.t0_text.empty() || *end != '\0' || !std::isfinite(v))
      throw std::runtime_error("--t0 must be a finite number of seconds or auto, got '" + c.t0_text + "'");
    c.t0_s = v;
  }
  c.time_channels = splitChannels(c.time_from_text);
}

std::string MissionProcessConfig::toString() const {
  std::ostringstream s;
  s << "mission: " << (mission_path.empty() ? "(none)" : mission_path) << "\n";
  s << "t0: " << (t0_s ? std::to_string(*t0_s) : std::string("auto (first data time)")) << "  # [s]\n";
  s << "time_from: [POSE";
  for (const auto& ch : time_channels) s << ", " << ch;
  s << "]\n";
  s << "stay: " << (stay ? "true" : "false") << "\n";
  s << "linger: " << linger_s << "  # [s] wall time\n";
  s << "status_period: " << status_period_s << "  # [s] data time\n";
  s << "resend_period: " << resend_period_s << "  # [s] data time\n";
  s << "heartbeat: " << heartbeat_s << "  # [s] wall time\n";
  s << "fleet: " << (fleet_path.empty() ? "(none)" : fleet_path) << "\n";
  if (!fleet_path.empty()) s << "bus: " << bus << "\n";
  return s.str();
}

MissionCompletion::MissionCompletion(const Mission& mission, double linger_s) : linger_s_(linger_s) {
  if (!mission.steps.empty() && mission.steps.back().action == MissionAction::Calibrate)
    last_calibrate_ = mission.steps.back();
  answered_ = !last_calibrate_;
}

int64_t MissionCompletion::attempts(const CalibStatus& s) {
  int64_t n = 0;
  for (const char* key : {"calibrations_ok", "calibrations_refused"}) {
    const auto it = s.counters.find(key);
    if (it != s.counters.end()) n += it->second;
  }
  return n;
}

void MissionCompletion::onCalibStatus(const CalibStatus& s) {
  attempts_seen_ = std::max(attempts_seen_, attempts(s));
  if (answered_ || !attempts_at_finish_) return;
  const int64_t expected = std::max<int64_t>(1, static_cast<int64_t>(last_calibrate_->anchors.size()));
  if (attempts(s) < *attempts_at_finish_ + expected) return;
  for (const auto& a : s.anchors) {
    const auto& ids = last_calibrate_->anchors;
    const bool named = ids.empty() || std::find(ids.begin(), ids.end(), a.id) != ids.end();
    if (named && a.state == "collecting") return;
  }
  answered_ = true;
}

void MissionCompletion::onFinished(int64_t wall_us) {
  if (finished_wall_us_) return;
  finished_wall_us_ = wall_us;
  attempts_at_finish_ = attempts_seen_;
}

bool MissionCompletion::done(int64_t wall_us) const {
  return finished_wall_us_ && (answered_ || timedOut(wall_us));
}

bool MissionCompletion::timedOut(int64_t wall_us) const {
  return finished_wall_us_ && !answered_ && static_cast<double>(wall_us - *finished_wall_us_) >= linger_s_ * 1e6;
}

}  // namespace meshnav::mission
