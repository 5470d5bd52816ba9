/// calibrator: the CalibratorNode (calibrator/node/calibrator_node.h) on LCM.
///   RANGE, POSE, ANCHORS, CALIB_CMD -> ANCHOR_INIT, CALIB_STATUS.
/// CALIB_STATUS goes out at the node's data-time rate, after every Calibrate command and, as the
/// process heartbeat, every --heartbeat seconds of wall time (also while no data flows).
#include <cmath>
#include <filesystem>
#include <memory>
#include <iostream>
#include <optional>
#include <set>

#include "calibrator/node/calibrator_node.h"
#include "calibrator/process/calibrator_process_config.h"
#include "common/dir_lock.h"
#include "common/setup.h"
#include "transport/channels.h"
#include "transport/input_journal.h"
#include "transport/process_main.h"

namespace {

using namespace meshnav;

void logAnchorInit(const AnchorInit& a) {
  spdlog::info("ANCHOR_INIT {} at t = {} s: p_AinG [{:.3f}, {:.3f}, {:.3f}] m, σ [{:.3f}, {:.3f}, {:.3f}] m, "
               "{} references, {} inliers, {} outliers",
               a.id, formatSeconds(a.t), a.p_AinG.x(), a.p_AinG.y(), a.p_AinG.z(), std::sqrt(a.cov_p_m2(0, 0)),
               std::sqrt(a.cov_p_m2(1, 1)), std::sqrt(a.cov_p_m2(2, 2)), a.biases.size(), a.n_inliers, a.n_outliers);
}

std::string anchorStates(const CalibStatus& st) {
  std::string out;
  for (const auto& a : st.anchors) out += fmt::format("{} {} ({} ranges); ", a.id, a.state, a.n_ranges);
  return out;
}

/// The CalibratorNode wired to LCM: its inputs journaled before they reach it, its outputs
/// published (except while the journal of a restart is replayed), the results file kept up to date.
class CalibratorProcess {
 public:
  CalibratorProcess(transport::ProcessMain& process, const calib::CalibratorProcessConfig& config,
                    const SystemSetup& setup)
      : process_(process),
        lcm_(process.lcm()),
        config_(config),
        node_(config.calibrator, setup, sinks(), config.node),
        results_file_(config.out_yaml),
        pose_period_(Duration::fromSec(config.pose_rate_hz > 0 ? 1.0 / config.pose_rate_hz : 0.0)) {}

  /// With --state-dir: replays the inputs a previous run journaled, then journals the new ones.
  void restoreFromJournal() {
    if (config_.state_dir.empty()) return;
    const std::string path = (std::filesystem::path(config_.state_dir) / "calibrator_inputs.lcmlog").string();
    replaying_ = true;
    Diagnostics& diag = lcm_.diagnostics();
    const int64_t n = transport::InputJournal::read(path, [&](const std::string& ch, const lcm::ReceiveBuffer& rb) {
      RangeSample r;
      PoseEstimate p;
      std::vector<AnchorEstimate> a;
      CalibCommand c;
      if (ch == channels::kRange.name && transport::InputJournal::decode(rb, channels::kRange, r, diag)) onRange(r);
      if (ch == channels::kPose.name && transport::InputJournal::decode(rb, channels::kPose, p, diag)) onPose(p);
      if (ch == channels::kPoseSmoothed.name && transport::InputJournal::decode(rb, channels::kPoseSmoothed, p, diag))
        onPoseSmoothed(p);
      if (ch == channels::kAnchors.name && transport::InputJournal::decode(rb, channels::kAnchors, a, diag)) onAnchors(a);
      if (ch == channels::kCalibCmd.name && transport::InputJournal::decode(rb, channels::kCalibCmd, c, diag)) onCommand(c);
    });
    replaying_ = false;
    if (n > 0)
      spdlog::warn("restart: {} inputs replayed from {} (data time {} s); anchors: {}", n, path,
                   node_.dataTime() ? formatSeconds(*node_.dataTime()) : std::string("none"),
                   anchorStates(node_.status()));
    journal_ = std::make_unique<transport::InputJournal>(path);
  }

  /// Subscribes the inputs and starts the CALIB_STATUS heartbeat (with a progress line every 10 s).
  void connect() {
    lcm_.subscribe(channels::kRange, [this](const RangeSample& r) { onRange(r); });
    lcm_.subscribe(channels::kPose, [this](const PoseEstimate& p) { onPose(p); });
    if (config_.smoothed_poses)
      lcm_.subscribe(channels::kPoseSmoothed, [this](const PoseEstimate& p) { onPoseSmoothed(p); });
    lcm_.subscribe(channels::kAnchors, [this](const std::vector<AnchorEstimate>& a) { onAnchors(a); });
    lcm_.subscribe(channels::kCalibCmd, [this](const CalibCommand& c) { onCommand(c); });
    const int64_t progress_period_us = 10'000'000;  // a progress line every 10 s of wall time
    next_progress_ = replay::wallUtimeNow() + progress_period_us;
    process_.heartbeat(channels::kCalibStatus, config_.heartbeat_s, [this] { return node_.status(); },
                       [this, progress_period_us](const CalibStatus& st) {
                         if (st.wall_utime < next_progress_ || !node_.dataTime()) return;
                         spdlog::info("t = {} s; anchors: {}", formatSeconds(st.t), anchorStates(st));
                         next_progress_ = st.wall_utime + progress_period_us;
                       });
  }

  /// After the loop: the last status, the results file, the counters.
  void finish() {
    const CalibStatus st = process_.stamped(node_.status());
    lcm_.publish(channels::kCalibStatus, st);
    // A second instance (transport/lcm_node.h) leaves the first one's results file alone.
    if (results_file_.enabled() && lcm_.secondInstance().empty()) writeResults(true);
    spdlog::info("stopped at t = {} s; anchors: {}counters: {}", formatSeconds(st.t), anchorStates(st),
                 transport::formatCounters(st.counters));
  }

 private:
  calib::CalibratorSinks sinks() {
    calib::CalibratorSinks s;
    s.anchor_init = [this](const AnchorInit& a) {
      logAnchorInit(a);
      if (!replaying_) lcm_.publish(channels::kAnchorInit, a);
    };
    s.status = [this](const CalibStatus& st) {
      if (!replaying_) lcm_.publish(channels::kCalibStatus, process_.stamped(st));
    };
    return s;
  }
  void writeResults(bool force) {
    const int64_t attempts = node_.diagnostics().get("calibrations_ok") + node_.diagnostics().get("calibrations_refused");
    if (results_file_.update(node_.results(), attempts, force))
      spdlog::info("calibration results written to {}", results_file_.path());
  }
  /// What the node consumes goes to the journal first, so a kill -9 right after loses nothing.
  template <class T>
  void journaled(channels::Channel<T> channel, const T& value, Timestamp t) {
    if (journal_ && !replaying_) journal_->write(channel, value, t.us);
  }
  void onRange(const RangeSample& r) {
    journaled(channels::kRange, r, r.t);
    node_.onRange(r);
    writeResults(false);  // automatic mode calibrates on data
  }
  void onPose(const PoseEstimate& p) {
    if (last_pose_ && p.t >= *last_pose_ && p.t - *last_pose_ < pose_period_) return;  // decimation
    last_pose_ = p.t;
    journaled(channels::kPose, p, p.t);
    node_.onPose(p);
    if (config_.smoothed_poses) awaiting_smoothed_.insert(p.t.us);
    writeResults(false);
  }
  /// A POSE_SMOOTHED of an instant the node took replaces that pose (the same instant: the newer
  /// wins, CalibratorNode::onPose); others are not needed (decimation).
  void onPoseSmoothed(const PoseEstimate& p) {
    const auto it = awaiting_smoothed_.find(p.t.us);
    if (it == awaiting_smoothed_.end()) return;
    awaiting_smoothed_.erase(awaiting_smoothed_.begin(), std::next(it));
    journaled(channels::kPoseSmoothed, p, p.t);
    node_.onPose(p);
  }
  void onAnchors(const std::vector<AnchorEstimate>& a) {
    journaled(channels::kAnchors, a, a.empty() ? Timestamp{} : a.front().t);
    node_.onAnchors(a);
  }
  void onCommand(const CalibCommand& c) {
    journaled(channels::kCalibCmd, c, c.t);
    node_.onCommand(c);
    writeResults(false);
  }

  transport::ProcessMain& process_;
  transport::LcmNode& lcm_;
  const calib::CalibratorProcessConfig& config_;
  bool replaying_ = false;  ///< while the journal is replayed: the results are known to the others
  calib::CalibratorNode node_;
  calib::CalibrationYamlWriter results_file_;
  std::unique_ptr<transport::InputJournal> journal_;
  std::optional<Timestamp> last_pose_;
  std::set<int64_t> awaiting_smoothed_;  ///< µs of the POSEs taken whose smoothed twin has not come (--smoothed-poses)
  Duration pose_period_;
  int64_t next_progress_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
  transport::ProcessMain process("calibrator", calib::kCalibratorProcessDescription);
  using Config = calib::CalibratorProcessConfig;
  return process.run<Config>(argc, argv, calib::declareCalibratorProcessOptions, [&](Config& config) {
    calib::loadCalibratorProcessConfig(config);
    process.require(!config.setup_path.empty() || config.print_config, "setup");
    SystemSetup setup;
    if (!config.setup_path.empty()) {
      setup = loadSetup(config.setup_path);
      calib::applySetup(config, setup);
    }
    if (config.print_config) {
      std::cout << config.toString();
      return 0;
    }
    // Its journal is this process's alone: a second calibrator on the folder is refused (exit 7).
    std::optional<DirLock> state_lock;
    if (!config.state_dir.empty()) state_lock.emplace(config.state_dir, "--state-dir");
    CalibratorProcess calibrator(process, config, setup);
    spdlog::info("calibrator options:\n{}", config.toString());
    calibrator.restoreFromJournal();
    calibrator.connect();
    spdlog::info("LCM {}; {} tags, {} known anchors; {}", process.lcm().url(), setup.rel_tag_positions.size(),
                 setup.abs_anchor_positions.size(),
                 config.node.auto_mode ? "automatic calibration" : "calibration on CALIB_CMD");
    const int rc = process.lcm().spin();
    calibrator.finish();
    return rc;
  });
}
