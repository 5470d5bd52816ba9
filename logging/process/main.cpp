/// logging: records the system's channels into the run files (estimate.csv, anchors.csv,
/// anchor_init.yaml, groundtruth.csv, summary.yaml) and optionally every message into an .lcmlog.
#include <lcm/lcm-cpp.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

#include "logging/run_recorder.h"
#include "transport/channels.h"
#include "transport/process_main.h"

namespace {

using namespace meshnav;

/// The --lcmlog file opened for writing (its folder created); throws naming it when it cannot be.
std::unique_ptr<lcm::LogFile> openLcmLog(const std::string& path, bool append) {
  const std::filesystem::path p(path);
  if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
  auto log = std::make_unique<lcm::LogFile>(p.string(), append ? "a" : "w");
  if (!log->good()) throw std::runtime_error(p.string() + ": cannot open for writing");
  return log;
}

}  // namespace

int main(int argc, char** argv) {
  transport::ProcessMain process(
      "logging",
      "Subscribes to every channel. Writes into --out: estimate.csv (POSE), anchors.csv (ANCHORS), anchor_init.yaml "
      "(ANCHOR_INIT), groundtruth.csv (GROUND_TRUTH), and on exit summary.yaml (messages per channel, last "
      "ESTIMATOR_STATUS / CALIB_STATUS / MISSION_STATUS, counters). Files (CSVs and --lcmlog) are flushed every "
      "--flush-period of wall time and on SIGINT/SIGTERM: a stop loses nothing received, a kill -9 at most the last "
      "period.");
  std::string out, lcmlog_path, channel_regex = ".*", run_id;
  double flush_period_s = 0.5, idle_s = 0.0;
  Cli& cli = process.cli();
  cli.optional("out", out, "output folder (created); required")->type_name("DIR");
  cli.optional("lcmlog", lcmlog_path, "also write every message of --channels into an LCM log (lcm-logplayer)")
      ->type_name("FILE");
  cli.option("channels", channel_regex, "channels recorded into --lcmlog and counted")->type_name("REGEX");
  cli.option("flush-period", flush_period_s, "seconds between flushes of the CSV files and the --lcmlog")
      ->type_name("S")
      ->check(cli::positive());
  cli.optional("exit-when-idle", idle_s,
               "exit once nothing arrived for S seconds after the first message (e.g. after an lcm-logplayer replay; "
               "default: run until stopped)")
      ->type_name("S")
      ->check(cli::nonNegative());
  cli.optional("run-id", run_id,
               "id of the run (launch files: ${T0_UTIME}); kept in OUT/.logging_run_id: a logger restarted with the "
               "id already there continues the files of its run instead of starting them anew")
      ->type_name("ID");
  cli.optionsFile("these options as a YAML map (`flush_period: 1`); the command line wins");

  return process.run(argc, argv, [&] {
    if (out.empty()) {
      spdlog::error("--out is required (see --help)");
      return 2;
    }
    // A restart within the same run (the supervisor respawned us): continue the files.
    bool append = false;
    const std::filesystem::path id_file = std::filesystem::path(out) / ".logging_run_id";
    if (!run_id.empty()) {
      std::string previous;
      if (std::ifstream in(id_file); in) std::getline(in, previous);
      append = previous == run_id;
      if (append) spdlog::warn("restart within run {}: continuing the files in {}", run_id, out);
    }
    logging::RunRecorder recorder(out, append);
    if (!run_id.empty()) std::ofstream(id_file) << run_id << "\n";
    transport::LcmNode& node = process.lcm();
    std::unique_ptr<lcm::LogFile> lcmlog = lcmlog_path.empty() ? nullptr : openLcmLog(lcmlog_path, append);
    int64_t last_msg_wall = 0;
    node.subscribeRaw(channel_regex, [&](const lcm::ReceiveBuffer& rbuf, const std::string& ch) {
      if (ch == "LCM_SELF_TEST") return;  // udpm's own start-up probe
      recorder.countMessage(ch, rbuf.data_size, rbuf.recv_utime);
      last_msg_wall = replay::wallUtimeNow();
      if (!lcmlog) return;
      lcm::LogEvent ev{0, rbuf.recv_utime, ch, static_cast<int32_t>(rbuf.data_size), rbuf.data};
      if (lcmlog->writeEvent(&ev) != 0) node.diagnostics().report("lcmlog:write_error", "lcmlog write failed");
    });
    node.subscribe(channels::kPose, [&](const PoseEstimate& e) { recorder.onPose(e); });
    node.subscribe(channels::kAnchors, [&](const std::vector<AnchorEstimate>& a) { recorder.onAnchors(a); });
    node.subscribe(channels::kAnchorInit, [&](const AnchorInit& a) { recorder.onAnchorInit(a); });
    node.subscribe(channels::kGroundTruth, [&](const PoseSample& p) { recorder.onGroundTruth(p); });
    node.subscribe(channels::kEstimatorStatus, [&](const EstimatorStatus& s) { recorder.onEstimatorStatus(s); });
    node.subscribe(channels::kCalibStatus, [&](const CalibStatus& s) { recorder.onCalibStatus(s); });
    node.subscribe(channels::kMissionStatus, [&](const MissionStatus& s) { recorder.onMissionStatus(s); });

    const int64_t progress_period_us = 10'000'000;
    int64_t next_progress = replay::wallUtimeNow() + progress_period_us;
    node.setHeartbeat(Duration::fromSec(flush_period_s), [&] {
      recorder.flush();
      if (lcmlog) std::fflush(lcmlog->getFilePtr());  // a kill -9 loses at most one flush period
      const int64_t now = replay::wallUtimeNow();
      if (now < next_progress) return;
      int64_t total = 0;
      for (const auto& [ch, c] : recorder.channels()) total += c.messages;
      spdlog::info("{} messages, {} poses, {} anchor rows so far", total, recorder.posesWritten(),
                   recorder.anchorRowsWritten());
      next_progress = now + progress_period_us;
    });
    spdlog::info("LCM {}; recording into {}{}", node.url(), out, lcmlog ? " and " + lcmlog_path : std::string());
    const int rc = node.spin([&] {
      return idle_s > 0 && last_msg_wall > 0 && replay::wallUtimeNow() - last_msg_wall > idle_s * 1e6;
    });
    recorder.finish(node.diagnostics());
    lcmlog.reset();
    spdlog::info("{}", recorder.summaryText());
    if (node.diagnostics().total() > 0) spdlog::warn("counters: {}", node.diagnostics().summary());
    return rc;
  });
}
