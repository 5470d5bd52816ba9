/// calibrator: the CalibratorNode (calibrator/node/calibrator_node.h) on LCM.
///   RANGE, POSE, ANCHORS, CALIB_CMD -> ANCHOR_INIT, CALIB_STATUS.
/// CALIB_STATUS goes out at the node's data-time rate, after every Calibrate command and, as the
/// process heartbeat, every --heartbeat seconds of wall time (also while no data flows).
#include <cmath>
#include <filesystem>
#include <memory>
#include <iostream>
#include <optional>

#include "calibrator/node/calibrator_node.h"
#include "calibrator/process/calibrator_process_config.h"
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

}  // namespace

int main(int argc, char** argv) {
  transport::ProcessMain process("calibrator", calib::kCalibratorProcessDescription);
  calib::CalibratorProcessConfig config;
  calib::declareCalibratorProcessOptions(process.cli(), config);
  return process.run(argc, argv, [&] {
    calib::loadCalibratorProcessConfig(config);
    if (config.setup_path.empty() && !config.print_config) {
      spdlog::error("--setup is required (see --help)");
      return 2;
    }
    SystemSetup setup;
    if (!config.setup_path.empty()) {
      setup = loadSetup(config.setup_path);
      calib::applySetup(config, setup);
    }
    if (config.print_config) {
      std::cout << config.toString();
      return 0;
    }
    transport::LcmNode& lcm = process.lcm();
    bool replaying = false;  // while the journal is replayed: the results are known to the others
    calib::CalibratorSinks sinks;
    sinks.anchor_init = [&](const AnchorInit& a) {
      logAnchorInit(a);
      if (!replaying) lcm.publish(channels::kAnchorInit, a);
    };
    sinks.status = [&](const CalibStatus& s) {
      if (!replaying) lcm.publish(channels::kCalibStatus, process.stamped(s));
    };
    calib::CalibratorNode node(config.calibrator, setup, sinks, config.node);
    spdlog::info("calibrator options:\n{}", config.toString());

    calib::CalibrationYamlWriter results_file(config.out_yaml);
    auto writeResults = [&](bool force) {
      const int64_t attempts =
          node.diagnostics().get("calibrations_ok") + node.diagnostics().get("calibrations_refused");
      if (results_file.update(node.results(), attempts, force))
        spdlog::info("calibration results written to {}", results_file.path());
    };
    std::optional<Timestamp> last_pose;
    const Duration pose_period = Duration::fromSec(config.pose_rate_hz > 0 ? 1.0 / config.pose_rate_hz : 0.0);
    // What the node consumed goes to the journal first, so a kill -9 right after loses nothing.
    std::unique_ptr<transport::InputJournal> journal;
    auto journaled = [&](auto channel, const auto& value, Timestamp t) {
      if (journal && !replaying) journal->write(channel, value, t.us);
    };
    auto onRange = [&](const RangeSample& r) {
      journaled(channels::kRange, r, r.t);
      node.onRange(r);
      writeResults(false);  // automatic mode calibrates on data
    };
    auto onPose = [&](const PoseEstimate& p) {
      if (last_pose && p.t >= *last_pose && p.t - *last_pose < pose_period) return;  // decimation
      last_pose = p.t;
      journaled(channels::kPose, p, p.t);
      node.onPose(p);
      writeResults(false);
    };
    auto onAnchors = [&](const std::vector<AnchorEstimate>& a) {
      journaled(channels::kAnchors, a, a.empty() ? Timestamp{} : a.front().t);
      node.onAnchors(a);
    };
    auto onCommand = [&](const CalibCommand& c) {
      journaled(channels::kCalibCmd, c, c.t);
      node.onCommand(c);
      writeResults(false);
    };
    if (!config.state_dir.empty()) {
      const std::string path = (std::filesystem::path(config.state_dir) / "calibrator_inputs.lcmlog").string();
      replaying = true;
      Diagnostics& diag = lcm.diagnostics();
      const int64_t n = transport::InputJournal::read(path, [&](const std::string& ch, const lcm::ReceiveBuffer& rb) {
        RangeSample r;
        PoseEstimate p;
        std::vector<AnchorEstimate> a;
        CalibCommand c;
        if (ch == channels::kRange.name && transport::InputJournal::decode(rb, channels::kRange, r, diag)) onRange(r);
        if (ch == channels::kPose.name && transport::InputJournal::decode(rb, channels::kPose, p, diag)) onPose(p);
        if (ch == channels::kAnchors.name && transport::InputJournal::decode(rb, channels::kAnchors, a, diag)) onAnchors(a);
        if (ch == channels::kCalibCmd.name && transport::InputJournal::decode(rb, channels::kCalibCmd, c, diag)) onCommand(c);
      });
      replaying = false;
      if (n > 0) {
        const CalibStatus st = node.status();
        spdlog::warn("restart: {} inputs replayed from {} (data time {} s); anchors: {}", n, path,
                     node.dataTime() ? formatSeconds(*node.dataTime()) : std::string("none"), anchorStates(st));
      }
      journal = std::make_unique<transport::InputJournal>(path);
    }
    lcm.subscribe(channels::kRange, onRange);
    lcm.subscribe(channels::kPose, onPose);
    lcm.subscribe(channels::kAnchors, onAnchors);
    lcm.subscribe(channels::kCalibCmd, onCommand);
    const int64_t progress_period_us = 10'000'000;  // a progress line every 10 s of wall time
    int64_t next_progress = replay::wallUtimeNow() + progress_period_us;
    process.heartbeat<CalibStatus>(channels::kCalibStatus, config.heartbeat_s, [&] { return node.status(); },
                                   [&](const CalibStatus& st) {
                                     if (st.wall_utime < next_progress || !node.dataTime()) return;
                                     spdlog::info("t = {} s; anchors: {}", formatSeconds(st.t), anchorStates(st));
                                     next_progress = st.wall_utime + progress_period_us;
                                   });
    spdlog::info("LCM {}; {} tags, {} known anchors; {}", lcm.url(), setup.rel_tag_positions.size(),
                 setup.abs_anchor_positions.size(),
                 config.node.auto_mode ? "automatic calibration" : "calibration on CALIB_CMD");
    const int rc = lcm.spin();

    const CalibStatus st = process.stamped(node.status());
    lcm.publish(channels::kCalibStatus, st);
    if (results_file.enabled()) writeResults(true);
    spdlog::info("stopped at t = {} s; anchors: {}counters: {}", formatSeconds(st.t), anchorStates(st),
                 transport::formatCounters(st.counters));
    return rc;
  });
}
