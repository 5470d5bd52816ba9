#include "transport/fleet_launch.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "transport/channels.h"
#include "transport/lcm_node.h"

namespace meshnav::transport {

namespace {

/// One process entry of the launch file.
void emitProcess(YAML::Emitter& y, const std::string& name, const std::string& command,
                 const std::vector<std::string>& args, bool required, double respawn_delay_s, int max_respawns) {
  y << YAML::BeginMap;
  y << YAML::Key << "name" << YAML::Value << name;
  y << YAML::Key << "command" << YAML::Value << "${BIN:-build/bin}/" + command;
  y << YAML::Key << "args" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (const std::string& a : args) y << a;
  y << YAML::EndSeq;
  if (required) y << YAML::Key << "required" << YAML::Value << true;
  y << YAML::Key << "respawn" << YAML::Value << "on-failure";
  if (respawn_delay_s > 0.0) y << YAML::Key << "respawn_delay" << YAML::Value << respawn_delay_s;
  y << YAML::Key << "max_respawns" << YAML::Value << max_respawns;
  y << YAML::EndMap;
}

std::string fmtSeconds(double s) {
  std::ostringstream o;
  o << s;
  return o.str();
}

}  // namespace

std::string fleetLaunchYaml(const std::vector<FleetEntry>& vehicles, const FleetLaunchOptions& o) {
  if (vehicles.empty()) throw std::invalid_argument("fleet launch: no vehicle");
  for (const FleetEntry& v : vehicles)
    if (const std::string why = channels::prefixProblem(v.name); !why.empty())
      throw std::invalid_argument("fleet launch: vehicle name " + why);
  if (!o.calibrator_for.empty() &&
      std::none_of(vehicles.begin(), vehicles.end(), [&](const FleetEntry& v) { return v.name == o.calibrator_for; }))
    throw std::invalid_argument("fleet launch: --calibrator-for '" + o.calibrator_for + "' is no vehicle of the fleet");
  if (o.fleet_calibrator && !o.calibrator_for.empty())
    throw std::invalid_argument("fleet launch: a fleet calibrator and --calibrator-for '" + o.calibrator_for +
                                "' exclude each other (the fleet's serves that vehicle too)");
  if (o.fleet_calibrator && o.source.empty())
    throw std::invalid_argument("fleet launch: the fleet calibrator needs the fleet file's path");
  // Each vehicle's bus, checked before anything is written.
  const std::string base_url = resolveLcmUrl(o.lcm_url);
  std::vector<std::string> bus_urls;
  for (size_t k = 0; k < vehicles.size(); ++k) bus_urls.push_back(vehicleLcmUrl(o.bus, base_url, k));
  std::vector<std::string> bridges, loggers;
  for (const FleetEntry& v : vehicles) {
    bridges.push_back(v.name + "_imu_bridge");
    bridges.push_back(v.name + "_uwb_bridge");
    if (o.logging) loggers.push_back(v.name + "_logging");
  }
  YAML::Emitter y;
  y << YAML::BeginMap;
  y << YAML::Key << "name" << YAML::Value << "fleet";
  y << YAML::Key << "stop_timeout" << YAML::Value << 5;
  y << YAML::Key << "t0_margin" << YAML::Value << 3.0;
  y << YAML::Key << "shutdown_after" << YAML::Value << YAML::Flow << bridges;
  y << YAML::Key << "shutdown_delay" << YAML::Value << o.shutdown_delay_s;
  if (o.logging) y << YAML::Key << "stop_last" << YAML::Value << YAML::Flow << loggers;
  y << YAML::Key << "processes" << YAML::Value << YAML::BeginSeq;
  const std::string wait = fmtSeconds(o.wait_timeout_s);
  if (o.fleet_calibrator) {
    // Not required, as a vehicle's own calibrator: navigation goes on without it. It opens every
    // vehicle's bus itself from the base URL (calibrator --fleet --bus).
    // --yield-cpu: below the estimators (under chrt one real-time level lower): a calibration of
    // the whole fleet's anchors takes ~0.1 s of one core and must not hold it from them.
    std::vector<std::string> args = {"--fleet", o.source, "--bus", toString(o.bus), "--yield-cpu"};
    if (o.bus == FleetBus::kPerVehicle || !o.lcm_url.empty()) args.insert(args.end(), {"--lcm-url", base_url});
    args.insert(args.end(), {"--config", "${CALIBRATOR_CONFIG:-" + o.calibrator_config + "}"});
    // A respawn resumes from its journal; a new launch (new T0_UTIME) never replays an older run's.
    if (o.logging) args.insert(args.end(), {"--state-dir", "${OUT}/fleet_calibrator_state/${T0_UTIME}"});
    emitProcess(y, "fleet_calibrator", "calibrator", args, false, 0.0, 5);
    if (!o.mission.empty()) {
      // It follows the first vehicle (its ESTIMATOR_STATUS and POSE on its bus, with the fleet's
      // CALIB_CMD) and sends ESTIMATOR_CMD to every vehicle on its bus (mission --fleet --bus).
      std::vector<std::string> m = {"--fleet", o.source, "--bus", toString(o.bus), "--yield-cpu"};
      if (o.bus == FleetBus::kPerVehicle || !o.lcm_url.empty()) m.insert(m.end(), {"--lcm-url", base_url});
      m.insert(m.end(), {"--mission", o.mission, "--t0", "${MISSION_T0:-0}"});
      emitProcess(y, "fleet_mission", "mission", m, false, 0.0, 3);
    }
  }
  if (o.peer_router && !o.source.empty() && vehicles.size() > 1) {
    // Not required: each vehicle navigates on its anchors without it. Not --yield-cpu: a
    // vehicle short of anchors waits on it. It opens every vehicle's bus itself (--bus).
    std::vector<std::string> args = {"--fleet", o.source, "--bus", toString(o.bus)};
    if (o.bus == FleetBus::kPerVehicle || !o.lcm_url.empty()) args.insert(args.end(), {"--lcm-url", base_url});
    // A respawn keeps whose information each vehicle holds (else it could send a vehicle's own
    // information back to it); a new launch (new T0_UTIME) never reads an older run's journal.
    if (o.logging) args.insert(args.end(), {"--state-dir", "${OUT}/fleet_peer_router_state/${T0_UTIME}"});
    // Back after 0.2 s as an estimator: a vehicle short of anchors has no peer ranges meanwhile.
    emitProcess(y, "fleet_peer_router", "peer_router", args, false, 0.2, 5);
  }
  for (size_t k = 0; k < vehicles.size(); ++k) {
    const FleetEntry& v = vehicles[k];
    const std::string& p = v.name;  // the vehicle's channel prefix
    // Every process of the vehicle: its prefix, and on its own bus (kPerVehicle) the bus's URL.
    auto on_bus = [&](std::vector<std::string> args) {
      std::vector<std::string> a = {"--channel-prefix", p};
      if (o.bus == FleetBus::kPerVehicle || !o.lcm_url.empty()) a.insert(a.end(), {"--lcm-url", bus_urls[k]});
      a.insert(a.end(), args.begin(), args.end());
      return a;
    };
    std::vector<std::string> est = on_bus({"--setup", v.dataset + "/setup.yaml", "--config",
                                           "${ESTIMATOR_CONFIG:-" + o.estimator_config + "}", "--heartbeat", "0.5"});
    if (o.logging) {
      est.push_back("--state-dir");
      est.push_back("${OUT}/" + p + "/estimator_state");  // a respawn resumes from it
    }
    emitProcess(y, p + "_estimator", "estimator", est, true, 0.2, 5);
    if (p == o.calibrator_for) {
      // Not required: navigation goes on without it (as in config/launch/flyby.yaml).
      emitProcess(y, p + "_calibrator", "calibrator",
                  on_bus({"--setup", v.dataset + "/setup.yaml", "--config",
                          "${CALIBRATOR_CONFIG:-" + o.calibrator_config + "}"}),
                  false, 0.0, 5);
      if (!o.mission.empty())
        emitProcess(y, p + "_mission", "mission", on_bus({"--mission", o.mission, "--t0", "${MISSION_T0:-0}"}),
                    false, 0.0, 3);
    }
    // The estimators answer first: the logger yields (--yield-cpu), the bridges one real-time
    // level (--yield-rt). Under a real-time policy every process of equal priority runs until it
    // blocks, so on two cores ten bridges waking with the estimators' inputs held RANGE -> POSE
    // p99 at 4-6.8 ms; one level below, 0.4-0.7 ms (docs/fleet.md "Who answers first"). A replay's
    // pacing lags more (max 25 -> 54 ms), which the estimators take as any arrival jitter. Without
    // a real-time policy the bridges keep their niceness: + 10 held the answers back (6-10 ms).
    if (o.logging)
      emitProcess(y, p + "_logging", "logging",
                  on_bus({"--out", "${OUT}/" + p, "--channels", p + "/.*", "--run-id", "${T0_UTIME}", "--yield-cpu"}),
                  true, 0.0, 5);
    for (const char* bridge : {"imu_bridge", "uwb_bridge"})
      emitProcess(y, p + "_" + bridge, bridge,
                  on_bus({"--dataset", v.dataset, "--rate", "${RATE:-1}", "--t0-utime", "${T0_UTIME}", "--data-t0",
                          "${DATA_T0:-0}", "--wait-for", "ESTIMATOR_STATUS", "--wait-timeout", wait, "--yield-rt"}),
                  false, 0.0, 3);
  }
  y << YAML::EndSeq << YAML::EndMap;
  if (!y.good()) throw std::runtime_error(std::string("fleet launch: YAML: ") + y.GetLastError());
  std::ostringstream out;
  out << "# A fleet over LCM (docs/fleet.md), generated by meshnav_fleet_launch"
      << (o.source.empty() ? std::string() : " from " + o.source) << ": do not edit, generate again.\n"
      << "# Per vehicle: its estimator, imu_bridge and uwb_bridge" << (o.logging ? " and logging" : "")
      << " on its own channels (--channel-prefix NAME)";
  if (o.bus == FleetBus::kPerVehicle) {
    out << " and its own LCM bus (--lcm-url):";
    for (size_t k = 0; k < vehicles.size(); ++k) out << (k ? ", " : " ") << vehicles[k].name << " " << bus_urls[k];
  } else {
    out << ", all on one LCM bus (" << (o.lcm_url.empty() ? "the environment's LCM_DEFAULT_URL" : o.lcm_url) << ")";
  }
  out << ".\n"
      << "# Variables: BIN, RATE (1), DATA_T0 (0), ESTIMATOR_CONFIG (" << o.estimator_config << ")"
      << (o.logging ? ", OUT (OUT/<vehicle>: the logger's files, the estimator's checkpoint)" : "") << ".\n"
      << y.c_str() << "\n";
  return out.str();
}

}  // namespace meshnav::transport
