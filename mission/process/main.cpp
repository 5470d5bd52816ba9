/// mission: the MissionNode (mission/mission_node.h) on LCM.
///   POSE, RANGE (data time), CALIB_STATUS, ESTIMATOR_STATUS -> CALIB_CMD, ESTIMATOR_CMD, MISSION_STATUS.
/// MISSION_STATUS goes out at the node's data-time rate and, as the process heartbeat, every
/// --heartbeat seconds of wall time.
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "common/fleet_file.h"
#include "mission/mission.h"
#include "mission/mission_node.h"
#include "mission/process/mission_process_config.h"
#include "transport/channels.h"
#include "transport/fleet_bus.h"
#include "transport/process_main.h"

namespace {

using namespace meshnav;

/// Subscribes the channels named in `names` (--time-channels) whose message time advances the
/// mission clock (besides POSE); each name is matched against the typed channel constants.
void subscribeTimeChannels(transport::LcmNode& lcm, const std::vector<std::string>& names,
                           const std::function<void(Timestamp)>& onDataTime) {
  auto timeOf = [&](auto channel) { lcm.subscribe(channel, [onDataTime](const auto& m) { onDataTime(m.t); }); };
  for (const auto& ch : names) {
    if (ch == channels::kRange.name)
      timeOf(channels::kRange);
    else if (ch == channels::kImu.name)
      timeOf(channels::kImu);
    else if (ch == channels::kBaro.name)
      timeOf(channels::kBaro);
    else if (ch == channels::kFlightState.name)
      timeOf(channels::kFlightState);
  }
}

}  // namespace

int main(int argc, char** argv) {
  transport::ProcessMain process("mission", mission::kMissionProcessDescription);
  using Config = mission::MissionProcessConfig;
  return process.run<Config>(argc, argv, mission::declareMissionProcessOptions, [&](Config& config) {
    mission::finishMissionProcessConfig(config);
    if (config.print_config) {
      std::cout << config.toString();
      return 0;
    }
    process.require(!config.mission_path.empty(), "mission");
    const mission::Mission script = mission::loadMission(config.mission_path);
    // Where ESTIMATOR_CMD goes: the followed vehicle's own channel, or with --fleet every
    // vehicle's on its bus (the first one's bus is the process's own: it follows that vehicle).
    std::vector<std::pair<transport::LcmNode*, std::string>> commanded;  // (bus, vehicle prefix)
    if (!config.fleet_path.empty()) {
      const std::vector<FleetEntry> fleet = loadFleetFile(config.fleet_path);
      const std::vector<transport::LcmNode*> buses =
          process.fleetBuses(fleet.size(), transport::parseFleetBus(config.bus), fleet[0].name);
      for (size_t k = 0; k < buses.size(); ++k) commanded.emplace_back(buses[k], fleet[k].name);
    } else {
      commanded.emplace_back(&process.lcm(), process.channelPrefix());
    }
    transport::LcmNode& lcm = process.lcm();
    mission::MissionSinks sinks;
    sinks.calib_cmd = [&](const CalibCommand& c) { lcm.publish(channels::kCalibCmd, c); };
    sinks.estimator_cmd = [&](const EstimatorCommand& c) {
      for (const auto& [node, prefix] : commanded) node->publishAs(prefix, channels::kEstimatorCmd, c);
    };
    sinks.status = [&](const MissionStatus& s) { lcm.publish(channels::kMissionStatus, process.stamped(s)); };
    mission::MissionNode node(script, sinks, mission::MissionNodeOptions{config.status_period_s, config.resend_period_s});
    if (config.t0_s) node.setT0(Timestamp::fromSec(*config.t0_s));
    mission::MissionCompletion completion(script, config.linger_s);
    spdlog::info("mission {}: {} steps; options:\n{}", config.mission_path, script.steps.size(), config.toString());

    mission::DataClock clock;
    auto onDataTime = [&](Timestamp t) {
      if (!clock.advance(t, lcm.diagnostics())) return;
      if (clock.rebased())
        node.onClockRebased(t);
      else
        node.onTime(t);
      if (node.finished() && !completion.finished()) {
        completion.onFinished(replay::wallUtimeNow());
        spdlog::info("mission finished at data t = {} s{}", formatSeconds(t),
                     config.stay ? " (staying: --stay)" : "; waiting for the calibrator's answer");
      }
    };
    lcm.subscribe(channels::kPose, [&](const PoseEstimate& p) { onDataTime(p.t); });
    subscribeTimeChannels(lcm, config.time_channels, onDataTime);
    lcm.subscribe(channels::kCalibStatus, [&](const CalibStatus& s) {
      node.onCalibStatus(s);
      completion.onCalibStatus(s);
    });
    lcm.subscribe(channels::kEstimatorStatus,
                                   [&](const EstimatorStatus& s) { node.onEstimatorStatus(s); });
    process.heartbeat<MissionStatus>(channels::kMissionStatus, config.heartbeat_s, [&] { return node.status(); });
    spdlog::info("LCM {}; {}waiting for data", lcm.url(),
                 commanded.size() > 1 ? "ESTIMATOR_CMD to " + std::to_string(commanded.size()) + " vehicles; " : "");

    const int rc = lcm.spin([&] { return !config.stay && completion.done(replay::wallUtimeNow()); });
    if (completion.timedOut(replay::wallUtimeNow()))
      spdlog::warn("no answer of the calibrator to the last step within {} s (--linger)", config.linger_s);
    const MissionStatus st = process.stamped(node.status());
    lcm.publish(channels::kMissionStatus, st);
    spdlog::info("{} at data t = {} s: {}", node.finished() ? "finished" : "stopped", formatSeconds(st.t), st.text);
    return rc;
  });
}
