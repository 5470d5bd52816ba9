/// imu_bridge: replays imu.csv, baro.csv and flight_state.csv of a dataset folder onto IMU, BARO
/// and FLIGHT_STATE, paced to the wall clock (see --help).
#include <spdlog/spdlog.h>

#include "common/cli.h"
#include "imu_bridge/inertial_streams.h"
#include "transport/channels.h"
#include "transport/lcm_node.h"
#include "transport/process_options.h"
#include "transport/replay_runner.h"

namespace {

const std::string kUsage = std::string(
    "imu_bridge --dataset DIR [options]\n"
    "  Publishes the inertial inputs of a dataset folder (DESIGN §6): imu.csv -> IMU,\n"
    "  baro.csv -> BARO, flight_state.csv -> FLIGHT_STATE (each file optional), time-sorted,\n"
    "  message utime = data time. Exits when the data is played (0), on SIGINT/SIGTERM (0),\n"
    "  on bad input (1) or when --wait-for timed out (3).\n"
    "  --dataset DIR      dataset folder\n"
    "  --no-imu, --no-baro, --no-flight-state   leave that stream out\n") +
    meshnav::transport::kReplayUsage + meshnav::transport::kProcessUsage;

}  // namespace

int main(int argc, char** argv) {
  using namespace meshnav;
  Cli cli("imu_bridge", kUsage);
  std::vector<std::string> names = {"dataset", "no-imu", "no-baro", "no-flight-state", "lcm-url", "log-level"};
  cli.option("dataset").option("no-imu", false).option("no-baro", false).option("no-flight-state", false);
  transport::declareProcessOptions(cli);
  transport::declareReplayOptions(cli);
  names.insert(names.end(), transport::replayOptionNames().begin(), transport::replayOptionNames().end());
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  transport::startProcess("imu_bridge", cli);
  try {
    const transport::OptionSource opts(cli, names);
    if (!opts.has("dataset")) {
      spdlog::error("--dataset is required\n{}", kUsage);
      return 2;
    }
    const auto replay_options = transport::replayOptionsFrom(opts);
    Diagnostics diag;
    imu::InertialStreams streams = imu::loadInertialStreams(opts.get("dataset"), diag);
    if (opts.flag("no-imu")) streams.imu.clear();
    if (opts.flag("no-baro")) streams.baro.clear();
    if (opts.flag("no-flight-state")) streams.flight_states.clear();
    if (diag.total() > 0) spdlog::warn("input problems (rows dropped): {}", diag.summary());
    const auto events = streams.timeline();

    transport::LcmNode node("imu_bridge", opts.get("lcm-url"));
    spdlog::info("LCM {}; {} messages to replay at {}", node.url(), events.size(),
                 replay_options.replay.rate > 0 ? fmt::format("{:g}x", replay_options.replay.rate) : "max speed");
    if (!transport::waitForStart(node, replay_options)) return node.stopRequested() ? 0 : 3;

    int64_t n[3] = {0, 0, 0};
    const auto progress = transport::runReplay(replay_options, events, [&](const replay::ReplayEvent& ev) {
      switch (ev.stream) {
        case imu::InertialStreams::kImuStream: node.publish(channels::kImu, streams.imu[ev.index]); break;
        case imu::InertialStreams::kBaroStream: node.publish(channels::kBaro, streams.baro[ev.index]); break;
        case imu::InertialStreams::kFlightStateStream:
          node.publish(channels::kFlightState, streams.flight_states[ev.index]);
          break;
      }
      ++n[ev.stream];
    });
    using imu::InertialStreams;
    spdlog::info("published IMU {}, BARO {}, FLIGHT_STATE {}{}", n[InertialStreams::kImuStream],
                 n[InertialStreams::kBaroStream], n[InertialStreams::kFlightStateStream],
                 node.diagnostics().total() ? ", errors: " + node.diagnostics().summary() : "");
    (void)progress;
    return node.diagnostics().get("lcm:publish_error") > 0 ? 1 : 0;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
