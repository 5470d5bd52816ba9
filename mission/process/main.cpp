/// mission: the MissionNode (mission/mission_node.h) on LCM.
///   POSE, RANGE (data time), CALIB_STATUS, ESTIMATOR_STATUS -> CALIB_CMD, ESTIMATOR_CMD, MISSION_STATUS.
/// The first POSE comes only after the estimator initialized, so data time (and t0 unless --t0 is
/// given) is taken from RANGE as well (--time-from). MISSION_STATUS goes out at the node's
/// data-time rate, after every step and, as the heartbeat, every --heartbeat seconds of wall time.
#include <spdlog/spdlog.h>

#include <iostream>

#include "common/cli.h"
#include "mission/mission.h"
#include "mission/mission_node.h"
#include "mission/process/mission_process_config.h"
#include "transport/channels.h"
#include "transport/lcm_node.h"
#include "transport/process_options.h"
#include "transport/replay/clock.h"

int main(int argc, char** argv) {
  using namespace meshnav;
  const std::string usage = std::string(mission::kMissionProcessUsage) + transport::kProcessUsage;
  Cli cli("mission", usage);
  mission::declareMissionProcessOptions(cli);
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  transport::startProcess("mission", cli);
  try {
    const mission::MissionProcessConfig config = mission::missionProcessConfig(cli);
    if (config.print_config) {
      std::cout << config.toString();
      return 0;
    }
    if (config.mission_path.empty()) {
      spdlog::error("--mission is required\n{}", usage);
      return 2;
    }
    if (cli.has("config")) spdlog::warn("--config is not used by mission (the script is --mission)");
    const mission::Mission script = mission::loadMission(config.mission_path);
    transport::LcmNode lcm("mission", cli.get("lcm-url"));

    auto stamped = [&lcm](MissionStatus st) {
      st.wall_utime = replay::wallUtimeNow();
      if (lcm.diagnostics().total() > 0) st.text += "; counters: " + lcm.diagnostics().summary();
      return st;
    };
    mission::MissionSinks sinks;
    sinks.calib_cmd = [&](const CalibCommand& c) { lcm.publish(channels::kCalibCmd, c); };
    sinks.estimator_cmd = [&](const EstimatorCommand& c) { lcm.publish(channels::kEstimatorCmd, c); };
    sinks.status = [&](const MissionStatus& s) { lcm.publish(channels::kMissionStatus, stamped(s)); };
    mission::MissionNode node(script, sinks, mission::MissionNodeOptions{config.status_period_s});
    if (config.t0_s) node.setT0(Timestamp::fromSec(*config.t0_s));
    mission::MissionCompletion completion(script, config.linger_s);
    spdlog::info("mission {}: {} steps; options:\n{}", config.mission_path, script.steps.size(), config.toString());

    mission::DataClock clock;
    auto onDataTime = [&](Timestamp t) {
      if (!clock.advance(t)) return;
      node.onTime(t);
      if (node.finished() && !completion.finished()) {
        completion.onFinished(replay::wallUtimeNow());
        spdlog::info("mission finished at data t = {} s{}", formatSeconds(t),
                     config.stay ? " (staying: --stay)" : "; waiting for the calibrator's answer");
      }
    };
    lcm.subscribe<PoseEstimate>(channels::kPose, [&](const PoseEstimate& p) { onDataTime(p.t); });
    for (const auto& ch : config.time_channels) {
      if (ch == channels::kRange)
        lcm.subscribe<RangeSample>(ch, [&](const RangeSample& m) { onDataTime(m.t); });
      else if (ch == channels::kImu)
        lcm.subscribe<ImuSample>(ch, [&](const ImuSample& m) { onDataTime(m.t); });
      else if (ch == channels::kBaro)
        lcm.subscribe<BaroSample>(ch, [&](const BaroSample& m) { onDataTime(m.t); });
      else if (ch == channels::kFlightState)
        lcm.subscribe<FlightStateSample>(ch, [&](const FlightStateSample& m) { onDataTime(m.t); });
    }
    lcm.subscribe<CalibStatus>(channels::kCalibStatus, [&](const CalibStatus& s) {
      node.onCalibStatus(s);
      completion.onCalibStatus(s);
    });
    lcm.subscribe<EstimatorStatus>(channels::kEstimatorStatus,
                                   [&](const EstimatorStatus& s) { node.onEstimatorStatus(s); });
    lcm.setHeartbeat(Duration::fromSec(config.heartbeat_s),
                     [&] { lcm.publish(channels::kMissionStatus, stamped(node.status())); });
    spdlog::info("LCM {}; waiting for data", lcm.url());

    const int rc = lcm.spin([&] { return !config.stay && completion.done(replay::wallUtimeNow()); });
    if (completion.timedOut(replay::wallUtimeNow()))
      spdlog::warn("no answer of the calibrator to the last step within {} s (--linger)", config.linger_s);
    const MissionStatus st = stamped(node.status());
    lcm.publish(channels::kMissionStatus, st);
    spdlog::info("{} at data t = {} s: {}", node.finished() ? "finished" : "stopped", formatSeconds(st.t), st.text);
    return rc;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
