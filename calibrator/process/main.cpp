/// calibrator: the CalibratorNode (calibrator/node/calibrator_node.h) on LCM.
///   RANGE, POSE, ANCHORS, CALIB_CMD -> ANCHOR_INIT, CALIB_STATUS.
/// CALIB_STATUS goes out at the node's data-time rate, after every Calibrate command and, as the
/// process heartbeat, every --heartbeat seconds of wall time (also while no data flows).
#include <cmath>
#include <iostream>
#include <optional>

#include "calibrator/node/calibrator_node.h"
#include "calibrator/process/calibrator_process_config.h"
#include "common/setup.h"
#include "transport/channels.h"
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
    calib::CalibratorSinks sinks;
    sinks.anchor_init = [&](const AnchorInit& a) {
      logAnchorInit(a);
      lcm.publish(channels::kAnchorInit, a);
    };
    sinks.status = [&](const CalibStatus& s) { lcm.publish(channels::kCalibStatus, process.stamped(s)); };
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
    lcm.subscribe<RangeSample>(channels::kRange, [&](const RangeSample& r) {
      node.onRange(r);
      writeResults(false);  // automatic mode calibrates on data
    });
    lcm.subscribe<PoseEstimate>(channels::kPose, [&](const PoseEstimate& p) {
      if (last_pose && p.t >= *last_pose && p.t - *last_pose < pose_period) return;  // decimation
      last_pose = p.t;
      node.onPose(p);
      writeResults(false);
    });
    lcm.subscribe<std::vector<AnchorEstimate>>(channels::kAnchors,
                                               [&](const std::vector<AnchorEstimate>& a) { node.onAnchors(a); });
    lcm.subscribe<CalibCommand>(channels::kCalibCmd, [&](const CalibCommand& c) {
      node.onCommand(c);
      writeResults(false);
    });
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
