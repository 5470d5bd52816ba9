/// estimator: the EstimatorNode (estimator/node/estimator_node.h) on LCM.
///   IMU, BARO, RANGE, FLIGHT_STATE, ANCHOR_INIT, ESTIMATOR_CMD -> POSE, POSE_SMOOTHED, ANCHORS, ESTIMATOR_STATUS.
/// ESTIMATOR_STATUS goes out at the node's data-time rate and, as the process heartbeat, every
/// --heartbeat seconds of wall time (also before any data arrives, so bridges can wait for it).
/// With --state-dir the node's checkpoint (estimator/restart/checkpoint.h) is written there every
/// --state-period seconds of data time and read back at start: a respawned estimator resumes
/// with its anchors (and its pose after a short outage) instead of starting over.
#include <chrono>
#include <iostream>
#include <thread>
#include <optional>
#include <set>

#include "common/dir_lock.h"
#include "common/setup.h"
#include "estimator/filter/strategy_factory.h"
#include "estimator/restart/checkpoint.h"
#include "estimator/node/estimator_node.h"
#include "transport/channels.h"
#include "transport/process_main.h"
#include "transport/time_sync.h"

namespace {

using namespace meshnav;

/// The process's own options (--lcm-url, --log-level come from transport::ProcessMain).
struct EstimatorProcessOptions {
  std::string setup_path, config_path, strategy, state_dir;
  double heartbeat_s = 1.0, state_period_s = 0.1, anchors_period_s = 2.0;
  bool print_config = false;
};

void declareOptions(Cli& cli, EstimatorProcessOptions& o) {
  cli.optional("setup", o.setup_path, "system setup (setup.yaml: tags, known anchors, pair biases, baro); required")
      ->type_name("FILE");
  cli.optional("config", o.config_path, "estimator options YAML (default: built-in = config/estimator.yaml)")
      ->type_name("FILE");
  cli.optional("strategy", o.strategy, "override the fusion strategy of --config: " + estimator::strategySummaries())
      ->check(cli::oneOf(estimator::strategyListed, estimator::strategyNames()));
  cli.option("heartbeat", o.heartbeat_s, "wall seconds between heartbeat statuses")->type_name("S")->check(cli::positive());
  cli.flag("print-config", o.print_config, "print the estimator options and exit");
  cli.optional("state-dir", o.state_dir, "folder of the restart checkpoint: written while running, resumed from at start")
      ->type_name("DIR");
  cli.option("state-period", o.state_period_s, "data seconds between two checkpoints")->type_name("S")->check(cli::positive());
  cli.option("anchors-period", o.anchors_period_s,
             "data seconds between two writes of the checkpoint's anchors (estimator_anchors.yaml, most of its cost); "
             "a change of the set of anchors is written at once")
      ->type_name("S")
      ->check(cli::positive());
}

/// The EstimatorNode wired to LCM, with its checkpoint in --state-dir.
class EstimatorProcess {
 public:
  EstimatorProcess(transport::ProcessMain& process, const EstimatorProcessOptions& o,
                   const estimator::EstimatorOptions& options, const SystemSetup& setup)
      : process_(process), lcm_(process.lcm()), o_(o), node_(options, setup, sinks()) {
    ready_ = true;
  }

  /// With --state-dir: resumes from the checkpoint found there (a bad one is reported, not used).
  void resumeFromCheckpoint() {
    if (o_.state_dir.empty()) return;
    try {
      if (auto c = estimator::readCheckpoint(o_.state_dir)) {
        spdlog::warn("restart: checkpoint of t = {} s with {} anchors in {}", formatSeconds(c->t), c->anchors.size(),
                     o_.state_dir);
        node_.resumeFrom(std::move(*c));
      }
    } catch (const std::exception& ex) {
      spdlog::error("checkpoint in {} not used: {}", o_.state_dir, ex.what());
    }
  }

  /// Subscribes the inputs, serves the time reference and starts the ESTIMATOR_STATUS heartbeat.
  void connect() {
    estimator::EstimatorNode& node = node_;
    // Every input kind (estimator/node/estimator_input.h) from the channel of its name and type;
    // a kind without such a channel (a dataset-only input) is not subscribed.
    estimator::forEachInputKind([&]<class T>() {
      constexpr auto channel = channels::find<T>(estimator::InputKind<T>::name);
      if constexpr (channel.name != nullptr) lcm_.subscribe(channel, [&node](const T& m) { node.onInput(m); });
    });
    // This host's clock is the reference of every stamp the estimator fuses: bridges on other
    // hosts estimate their offset to it (transport/time_sync.h, docs/deployment.md).
    transport::serveTimeSync(lcm_);
    process_.heartbeat(channels::kEstimatorStatus, o_.heartbeat_s, [&node] { return node.status(); },
                       [this](const EstimatorStatus& st) {
                         if (!st.initialized || was_initialized_) return;
                         was_initialized_ = true;
                         spdlog::info("initialized at t = {} s", formatSeconds(st.t));
                       });
  }

  /// After the loop: the final anchors and status, for the recorder.
  void finish() {
    // A re-run done on its worker comes in before the final anchors; one still running is dropped
    // (waiting could outlast the supervisor's stop timeout under a sanitizer).
    node_.flushHeld();  // measurements waiting for an IMU sample that will not come
    node_.stopRerun();
    finishing_ = true;
    node_.flushSmoothed();  // the last fixed_lag.lag_s of POSE_SMOOTHED, with the data there is
    if (node_.initialized()) lcm_.publish(channels::kAnchors, node_.anchors());
    const EstimatorStatus st = process_.stamped(node_.status());
    lcm_.publish(channels::kEstimatorStatus, st);
    spdlog::info("stopped at t = {} s ({}); counters: {}", formatSeconds(st.t),
                 st.initialized ? "initialized" : "never initialized", transport::formatCounters(st.counters));
    // The filter's steps (as timings.csv of meshnav run): what a handler's time is made of.
    std::string steps;
    for (const auto& [type, t] : node_.timings().stats())
      steps += fmt::format("{}{} n {} mean {:.0f} µs max {:.1f} ms", steps.empty() ? "" : "; ", type, t.count, t.mean_us,
                           t.max_us / 1000.0);
    if (!steps.empty()) spdlog::info("filter steps: {}", steps);
  }

  const estimator::EstimatorNode& node() const { return node_; }

 private:
  estimator::EstimatorSinks sinks() {
    estimator::EstimatorSinks s;
    s.pose = [this](const PoseEstimate& e) {
      lcm_.publish(channels::kPose, e);
      checkpoint(e.t);
    };
    // POSE_SMOOTHED: the fixed-lag smoother's poses (fixed_lag.enabled; after their POSE, never before).
    s.pose_smoothed = [this](const PoseEstimate& e) {
      lcm_.publish(channels::kPoseSmoothed, e);
      // At the end (flushSmoothed) the last lag_s of poses go out at once: paced, so that a
      // subscriber's socket buffer (about 200 kB) takes them (running, the node spreads them).
      if (finishing_ && ++finish_published_ % 64 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    };
    s.anchors = [this](const std::vector<AnchorEstimate>& a) { lcm_.publish(channels::kAnchors, a); };
    s.status = [this](const EstimatorStatus& st) { lcm_.publish(channels::kEstimatorStatus, process_.stamped(st)); };
    return s;
  }
  /// Writes the checkpoint every --state-period of data time (with --state-dir).
  void checkpoint(Timestamp t) {
    if (o_.state_dir.empty() || !ready_ || (last_checkpoint_ && (t - *last_checkpoint_).sec() < o_.state_period_s))
      return;
    if (!lcm_.secondInstance().empty()) return;  // a second instance leaves the first one's checkpoint alone
    last_checkpoint_ = t;
    try {
      std::set<SensorId> ids = node_.estimatedAnchorIds();
      const bool anchors = !last_anchors_ || ids != anchor_ids_ || (t - *last_anchors_).sec() >= o_.anchors_period_s ||
                           !estimator::checkpointHasAnchorsFile(o_.state_dir);
      // The anchors' part is gathered only when its file is written.
      estimator::writeCheckpoint(node_.checkpoint(anchors), o_.state_dir, anchors);
      if (anchors) {
        last_anchors_ = t;
        anchor_ids_ = std::move(ids);
      }
    } catch (const std::exception& ex) {
      spdlog::error("checkpoint not written: {}", ex.what());
    }
  }

  transport::ProcessMain& process_;
  transport::LcmNode& lcm_;
  const EstimatorProcessOptions& o_;
  std::optional<Timestamp> last_checkpoint_;
  std::optional<Timestamp> last_anchors_;  ///< data time of the last write of the anchors' file
  std::set<SensorId> anchor_ids_;          ///< the anchors it holds
  bool was_initialized_ = false;
  bool finishing_ = false;  ///< in finish(): POSE_SMOOTHED paced
  int64_t finish_published_ = 0;
  bool ready_ = false;  ///< false while node_ is constructed: no checkpoint from inside its constructor
  estimator::EstimatorNode node_;
};

}  // namespace

int main(int argc, char** argv) {
  transport::ProcessMain process(
      "estimator",
      "Subscribes IMU, BARO, RANGE, FLIGHT_STATE, ANCHOR_INIT, ESTIMATOR_CMD; publishes POSE, POSE_SMOOTHED "
      "(fixed-lag smoothed poses, estimator.yaml fixed_lag), ANCHORS and ESTIMATOR_STATUS (also a wall-clock heartbeat). Messages may arrive out of order: the node re-processes "
      "within its window. Malformed messages are counted per channel (\"<CHANNEL>:decode_error\" / "
      "\":invalid_message\") and reported in ESTIMATOR_STATUS.");
  return process.run<EstimatorProcessOptions>(argc, argv, declareOptions, [&](EstimatorProcessOptions& o) {
    estimator::EstimatorOptions options;
    if (!o.config_path.empty()) options = estimator::EstimatorOptions::fromYaml(o.config_path);
    if (!o.strategy.empty()) options.strategy = o.strategy;
    // A re-run must not stop the POSE stream here (docs/modular_estimator.md, "Re-run on anchor join").
    if (options.refine.rerun_mode == "auto") options.refine.rerun_mode = "async";
    if (o.print_config) {
      std::cout << options.toString();
      return 0;
    }
    process.require(!o.setup_path.empty(), "setup");
    const SystemSetup setup = loadSetup(o.setup_path);
    // Its checkpoint is this process's alone: a second estimator on the folder is refused (exit 7).
    std::optional<DirLock> state_lock;
    if (!o.state_dir.empty()) state_lock.emplace(o.state_dir, "--state-dir");
    EstimatorProcess estimator(process, o, options, setup);
    estimator.resumeFromCheckpoint();
    spdlog::info("estimator options:\n{}", estimator.node().options().toString());
    estimator.connect();
    spdlog::info("LCM {}; strategy {}; {} tags, {} known anchors", process.lcm().url(), options.strategy,
                 setup.rel_tag_positions.size(), setup.abs_anchor_positions.size());
    const int rc = process.lcm().spin();
    estimator.finish();
    return rc;
  });
}
