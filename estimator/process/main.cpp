/// estimator: the EstimatorNode (estimator/node/estimator_node.h) on LCM.
///   IMU, BARO, RANGE, FLIGHT_STATE, ANCHOR_INIT, ESTIMATOR_CMD -> POSE, ANCHORS, ESTIMATOR_STATUS.
/// ESTIMATOR_STATUS goes out at the node's data-time rate and, as the process heartbeat, every
/// --heartbeat seconds of wall time (also before any data arrives, so bridges can wait for it).
#include <spdlog/spdlog.h>

#include <iostream>

#include "common/cli.h"
#include "common/setup.h"
#include "estimator/node/estimator_node.h"
#include "transport/channels.h"
#include "transport/lcm_node.h"
#include "transport/process_options.h"
#include "transport/replay/clock.h"

namespace {

const std::string kUsage = std::string(
    "estimator --setup FILE [--config FILE] [options]\n"
    "  Subscribes IMU, BARO, RANGE, FLIGHT_STATE, ANCHOR_INIT, ESTIMATOR_CMD; publishes POSE,\n"
    "  ANCHORS and ESTIMATOR_STATUS (also a wall-clock heartbeat). Messages may arrive out of\n"
    "  order: the node re-processes within its window. Malformed messages are counted per channel\n"
    "  (\"<CHANNEL>:decode_error\" / \":invalid_message\") and reported in ESTIMATOR_STATUS.\n"
    "  --setup FILE       system setup (setup.yaml: tags, known anchors, pair biases, baro)\n"
    "  --config FILE      estimator options YAML (default: built-in = config/estimator.yaml)\n"
    "  --strategy S       override the fusion strategy of --config (centralized|dp|dah)\n"
    "  --heartbeat S      wall seconds between heartbeat statuses (default 1)\n"
    "  --print-config     print the estimator options and exit\n") +
    meshnav::transport::kProcessUsage;

}  // namespace

int main(int argc, char** argv) {
  using namespace meshnav;
  Cli cli("estimator", kUsage);
  cli.option("setup").option("strategy").option("heartbeat").option("print-config", false);
  transport::declareProcessOptions(cli);
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  transport::startProcess("estimator", cli);
  try {
    estimator::EstimatorOptions options;
    if (cli.has("config")) options = estimator::EstimatorOptions::fromYaml(cli.get("config"));
    if (cli.has("strategy")) options.strategy = cli.get("strategy");
    if (cli.has("print-config")) {
      std::cout << options.toString();
      return 0;
    }
    if (!cli.has("setup")) {
      spdlog::error("--setup is required\n{}", kUsage);
      return 2;
    }
    const SystemSetup setup = loadSetup(cli.get("setup"));
    transport::LcmNode lcm("estimator", cli.get("lcm-url"));

    /// Status as published: the node's, plus the process's own counters (malformed messages).
    auto fullStatus = [&lcm](EstimatorStatus st) {
      st.wall_utime = replay::wallUtimeNow();
      for (const auto& [k, v] : lcm.diagnostics().snapshot()) st.counters[k] += v;
      return st;
    };
    estimator::EstimatorSinks sinks;
    sinks.pose = [&](const PoseEstimate& e) { lcm.publish(channels::kPose, e); };
    sinks.anchors = [&](const std::vector<AnchorEstimate>& a) { lcm.publish(channels::kAnchors, a); };
    sinks.status = [&](const EstimatorStatus& s) { lcm.publish(channels::kEstimatorStatus, fullStatus(s)); };
    estimator::EstimatorNode node(options, setup, sinks);
    spdlog::info("estimator options:\n{}", node.options().toString());

    lcm.subscribe<ImuSample>(channels::kImu, [&](const ImuSample& s) { node.onImu(s); });
    lcm.subscribe<BaroSample>(channels::kBaro, [&](const BaroSample& s) { node.onBaro(s); });
    lcm.subscribe<RangeSample>(channels::kRange, [&](const RangeSample& s) { node.onRange(s); });
    lcm.subscribe<FlightStateSample>(channels::kFlightState, [&](const FlightStateSample& s) { node.onFlightState(s); });
    lcm.subscribe<AnchorInit>(channels::kAnchorInit, [&](const AnchorInit& a) { node.onAnchorInit(a); });
    lcm.subscribe<EstimatorCommand>(channels::kEstimatorCmd, [&](const EstimatorCommand& c) { node.onCommand(c); });

    bool was_initialized = false;
    lcm.setHeartbeat(Duration::fromSec(cli.getDouble("heartbeat", 1.0)), [&] {
      lcm.publish(channels::kEstimatorStatus, fullStatus(node.status()));
      if (node.initialized() && !was_initialized) {
        was_initialized = true;
        spdlog::info("initialized at t = {} s", formatSeconds(node.status().t));
      }
    });
    spdlog::info("LCM {}; strategy {}; {} tags, {} known anchors", lcm.url(), options.strategy,
                 setup.rel_tag_positions.size(), setup.abs_anchor_positions.size());
    const int rc = lcm.spin();

    // Final state for the recorder.
    if (node.initialized()) lcm.publish(channels::kAnchors, node.anchors());
    const EstimatorStatus st = fullStatus(node.status());
    lcm.publish(channels::kEstimatorStatus, st);
    std::string counters;
    for (const auto& [k, v] : st.counters) counters += fmt::format("{}={} ", k, v);
    spdlog::info("stopped at t = {} s ({}); counters: {}", formatSeconds(st.t),
                 st.initialized ? "initialized" : "never initialized", counters);
    return rc;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
