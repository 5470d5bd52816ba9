/// imu_bridge: replays imu.csv, baro.csv and flight_state.csv of a dataset folder onto IMU, BARO
/// and FLIGHT_STATE, paced to the wall clock (see --help).
#include "imu_bridge/inertial_streams.h"
#include "transport/channels.h"
#include "transport/process_main.h"
#include "transport/replay_runner.h"

int main(int argc, char** argv) {
  using namespace meshnav;
  transport::ProcessMain process(
      "imu_bridge",
      "Publishes the inertial inputs of a dataset folder: imu.csv -> IMU, baro.csv -> BARO, flight_state.csv -> "
      "FLIGHT_STATE, height.csv -> HEIGHT (each file optional), time-sorted, message utime = data time. Exits when the data is played "
      "(0; with --drain once the estimator has processed the last IMU sample), on SIGINT/SIGTERM (0), on bad input "
      "(1) or when --wait-for timed out (3).");
  std::string dataset;
  bool no_imu = false, no_baro = false, no_flight_state = false, no_height = false;
  transport::ReplayCliValues replay_values;
  Cli& cli = process.cli();
  cli.optional("dataset", dataset, "dataset folder; required")->type_name("DIR");
  cli.flag("no-imu", no_imu, "leave imu.csv out");
  cli.flag("no-baro", no_baro, "leave baro.csv out");
  cli.flag("no-flight-state", no_flight_state, "leave flight_state.csv out");
  cli.flag("no-height", no_height, "leave height.csv out");
  transport::declareReplayOptions(cli, replay_values);
  cli.optionsFile("these options as a YAML map (`rate: 10`, `wait_for: ESTIMATOR_STATUS`); the command line wins");

  return process.run(argc, argv, [&] {
    process.require(!dataset.empty(), "dataset");
    const auto replay_options = transport::replayOptionsFrom(cli, replay_values);
    Diagnostics diag;
    imu::InertialStreams streams = imu::loadInertialStreams(dataset, diag);
    if (no_imu) streams.imu.clear();
    if (no_baro) streams.baro.clear();
    if (no_flight_state) streams.flight_states.clear();
    if (no_height) streams.heights.clear();
    if (diag.total() > 0) spdlog::warn("input problems (rows dropped): {}", diag.summary());
    const auto events = streams.timeline();

    transport::LcmNode& node = process.lcm();
    spdlog::info("LCM {}; {} messages to replay at {}", node.url(), events.size(),
                 replay_options.replay.rate > 0 ? fmt::format("{:g}x", replay_options.replay.rate) : "max speed");
    if (!transport::waitForStart(node, replay_options)) return node.stopRequested() ? 0 : 3;

    using imu::InertialStreams;
    int64_t n[4] = {0, 0, 0, 0};
    Timestamp last_imu_t;  // what --drain waits for the estimator to have processed
    const auto progress = transport::runReplay(replay_options, events, [&](const replay::ReplayEvent& ev) {
      switch (ev.stream) {
        case InertialStreams::kImuStream:
          node.publish(channels::kImu, streams.imu[ev.index]);
          last_imu_t = streams.imu[ev.index].t;
          break;
        case InertialStreams::kBaroStream: node.publish(channels::kBaro, streams.baro[ev.index]); break;
        case InertialStreams::kFlightStateStream: node.publish(channels::kFlightState, streams.flight_states[ev.index]); break;
        case InertialStreams::kHeightStream: node.publish(channels::kHeight, streams.heights[ev.index]); break;
      }
      ++n[ev.stream];
    });
    spdlog::info("published IMU {}, BARO {}, FLIGHT_STATE {}, HEIGHT {}{}", n[InertialStreams::kImuStream],
                 n[InertialStreams::kBaroStream], n[InertialStreams::kFlightStateStream], n[InertialStreams::kHeightStream],
                 node.diagnostics().total() ? ", errors: " + node.diagnostics().summary() : "");
    if (!progress.stopped && n[InertialStreams::kImuStream] > 0) transport::waitForDrain(node, replay_options, last_imu_t);
    return node.diagnostics().get("lcm:publish_error") > 0 ? 1 : 0;
  });
}
