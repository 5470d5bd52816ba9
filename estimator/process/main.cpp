/// estimator: the EstimatorNode (estimator/node/estimator_node.h) on LCM.
///   IMU, BARO, RANGE, FLIGHT_STATE, ANCHOR_INIT, ESTIMATOR_CMD -> POSE, ANCHORS, ESTIMATOR_STATUS.
/// ESTIMATOR_STATUS goes out at the node's data-time rate and, as the process heartbeat, every
/// --heartbeat seconds of wall time (also before any data arrives, so bridges can wait for it).
/// With --state-dir the node's checkpoint (estimator/node/checkpoint.h) is written there every
/// --state-period seconds of data time and read back at start: a respawned estimator resumes
/// with its anchors (and its pose after a short outage) instead of starting over.
#include <iostream>

#include "common/setup.h"
#include "estimator/filter/strategy_factory.h"
#include "estimator/node/checkpoint.h"
#include "estimator/node/estimator_node.h"
#include "transport/channels.h"
#include "transport/process_main.h"
#include "transport/time_sync.h"

int main(int argc, char** argv) {
  using namespace meshnav;
  transport::ProcessMain process(
      "estimator",
      "Subscribes IMU, BARO, RANGE, FLIGHT_STATE, ANCHOR_INIT, ESTIMATOR_CMD; publishes POSE, ANCHORS and "
      "ESTIMATOR_STATUS (also a wall-clock heartbeat). Messages may arrive out of order: the node re-processes "
      "within its window. Malformed messages are counted per channel (\"<CHANNEL>:decode_error\" / "
      "\":invalid_message\") and reported in ESTIMATOR_STATUS.");
  std::string setup_path, config_path, strategy, state_dir;
  double heartbeat_s = 1.0, state_period_s = 0.5;
  bool print_config = false;
  Cli& cli = process.cli();
  cli.optional("setup", setup_path, "system setup (setup.yaml: tags, known anchors, pair biases, baro); required")
      ->type_name("FILE");
  cli.optional("config", config_path, "estimator options YAML (default: built-in = config/estimator.yaml)")
      ->type_name("FILE");
  cli.optional("strategy", strategy, "override the fusion strategy of --config")
      ->check(cli::oneOf(estimator::strategyImplemented, "centralized|dp|dah"));
  cli.option("heartbeat", heartbeat_s, "wall seconds between heartbeat statuses")->type_name("S")->check(cli::positive());
  cli.flag("print-config", print_config, "print the estimator options and exit");
  cli.optional("state-dir", state_dir, "folder of the restart checkpoint: written while running, resumed from at start")
      ->type_name("DIR");
  cli.option("state-period", state_period_s, "data seconds between two checkpoints")->type_name("S")->check(cli::positive());

  return process.run(argc, argv, [&] {
    estimator::EstimatorOptions options;
    if (!config_path.empty()) options = estimator::EstimatorOptions::fromYaml(config_path);
    if (!strategy.empty()) options.strategy = strategy;
    if (print_config) {
      std::cout << options.toString();
      return 0;
    }
    if (setup_path.empty()) {
      spdlog::error("--setup is required (see --help)");
      return 2;
    }
    const SystemSetup setup = loadSetup(setup_path);
    transport::LcmNode& lcm = process.lcm();
    estimator::EstimatorSinks sinks;
    estimator::EstimatorNode* node_ptr = nullptr;
    std::optional<Timestamp> last_checkpoint;
    sinks.pose = [&](const PoseEstimate& e) {
      lcm.publish(channels::kPose, e);
      if (state_dir.empty() || !node_ptr || (last_checkpoint && (e.t - *last_checkpoint).sec() < state_period_s)) return;
      last_checkpoint = e.t;
      try {
        estimator::writeCheckpoint(node_ptr->checkpoint(), state_dir);
      } catch (const std::exception& ex) {
        spdlog::error("checkpoint not written: {}", ex.what());
      }
    };
    sinks.anchors = [&](const std::vector<AnchorEstimate>& a) { lcm.publish(channels::kAnchors, a); };
    sinks.status = [&](const EstimatorStatus& s) { lcm.publish(channels::kEstimatorStatus, process.stamped(s)); };
    estimator::EstimatorNode node(options, setup, sinks);
    node_ptr = &node;
    if (!state_dir.empty()) {
      try {
        if (auto c = estimator::readCheckpoint(state_dir)) {
          spdlog::warn("restart: checkpoint of t = {} s with {} anchors in {}", formatSeconds(c->t), c->anchors.size(),
                       state_dir);
          node.resumeFrom(std::move(*c));
        }
      } catch (const std::exception& ex) {
        spdlog::error("checkpoint in {} not used: {}", state_dir, ex.what());
      }
    }
    spdlog::info("estimator options:\n{}", node.options().toString());

    lcm.subscribe(channels::kImu, [&](const ImuSample& s) { node.onImu(s); });
    lcm.subscribe(channels::kBaro, [&](const BaroSample& s) { node.onBaro(s); });
    lcm.subscribe(channels::kHeight, [&](const HeightSample& s) { node.onHeight(s); });
    lcm.subscribe(channels::kRange, [&](const RangeSample& s) { node.onRange(s); });
    lcm.subscribe(channels::kFlightState, [&](const FlightStateSample& s) { node.onFlightState(s); });
    lcm.subscribe(channels::kAnchorInit, [&](const AnchorInit& a) { node.onAnchorInit(a); });
    lcm.subscribe(channels::kEstimatorCmd, [&](const EstimatorCommand& c) { node.onCommand(c); });
    // This host's clock is the reference of every stamp the estimator fuses: bridges on other
    // hosts estimate their offset to it (transport/time_sync.h, docs/deployment.md).
    transport::serveTimeSync(lcm);

    bool was_initialized = false;
    process.heartbeat<EstimatorStatus>(channels::kEstimatorStatus, heartbeat_s, [&] { return node.status(); },
                                       [&](const EstimatorStatus& st) {
                                         if (!st.initialized || was_initialized) return;
                                         was_initialized = true;
                                         spdlog::info("initialized at t = {} s", formatSeconds(st.t));
                                       });
    spdlog::info("LCM {}; strategy {}; {} tags, {} known anchors", lcm.url(), options.strategy,
                 setup.rel_tag_positions.size(), setup.abs_anchor_positions.size());
    const int rc = lcm.spin();

    // Final state for the recorder.
    if (node.initialized()) lcm.publish(channels::kAnchors, node.anchors());
    const EstimatorStatus st = process.stamped(node.status());
    lcm.publish(channels::kEstimatorStatus, st);
    spdlog::info("stopped at t = {} s ({}); counters: {}", formatSeconds(st.t),
                 st.initialized ? "initialized" : "never initialized", transport::formatCounters(st.counters));
    return rc;
  });
}
