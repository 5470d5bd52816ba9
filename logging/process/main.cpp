/// logging: records the system's channels into the files of DESIGN §6 (estimate.csv, anchors.csv,
/// anchor_init.yaml, groundtruth.csv, summary.yaml) and optionally every message into an .lcmlog.
#include <lcm/lcm-cpp.hpp>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <memory>

#include "common/cli.h"
#include "logging/run_recorder.h"
#include "transport/channels.h"
#include "transport/lcm_node.h"
#include "transport/option_source.h"
#include "transport/process_options.h"
#include "transport/replay/clock.h"

namespace {

const std::string kUsage = std::string(
    "logging --out DIR [--lcmlog FILE] [options]\n"
    "  Subscribes to every channel. Writes into DIR: estimate.csv (POSE), anchors.csv (ANCHORS),\n"
    "  anchor_init.yaml (ANCHOR_INIT), groundtruth.csv (GROUND_TRUTH), and on exit summary.yaml\n"
    "  (messages per channel, last ESTIMATOR_STATUS / CALIB_STATUS / MISSION_STATUS, counters).\n"
    "  Files are flushed every --flush-period and on SIGINT/SIGTERM.\n"
    "  --out DIR            output folder (created)\n"
    "  --lcmlog FILE        also write every message of --channels into an LCM log (lcm-logplayer)\n"
    "  --channels REGEX     channels recorded into --lcmlog and counted (default: .*)\n"
    "  --flush-period S     seconds between flushes of the CSV files (default 0.5)\n"
    "  --exit-when-idle S   exit once nothing arrived for S seconds after the first message\n"
    "                       (e.g. after an lcm-logplayer replay; default: run until stopped)\n") +
    meshnav::transport::kProcessUsage;

}  // namespace

int main(int argc, char** argv) {
  using namespace meshnav;
  Cli cli("logging", kUsage);
  const std::vector<std::string> names = {"out", "lcmlog", "channels", "flush-period", "exit-when-idle", "lcm-url",
                                          "log-level"};
  for (const auto& n : names) cli.option(n);
  transport::declareProcessOptions(cli);
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  transport::startProcess("logging", cli);
  try {
    const transport::OptionSource opts(cli, names);
    if (!opts.has("out")) {
      spdlog::error("--out is required\n{}", kUsage);
      return 2;
    }
    logging::RunRecorder recorder(opts.get("out"));
    transport::LcmNode node("logging", opts.get("lcm-url"));

    std::unique_ptr<lcm::LogFile> lcmlog;
    if (opts.has("lcmlog")) {
      const std::filesystem::path p(opts.get("lcmlog"));
      if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
      lcmlog = std::make_unique<lcm::LogFile>(p.string(), "w");
      if (!lcmlog->good()) {
        spdlog::error("{}: cannot open for writing", p.string());
        return 1;
      }
    }
    int64_t last_msg_wall = 0;
    node.subscribeRaw(opts.get("channels", ".*"), [&](const lcm::ReceiveBuffer& rbuf, const std::string& ch) {
      if (ch == "LCM_SELF_TEST") return;  // udpm's own start-up probe
      recorder.countMessage(ch, rbuf.data_size, rbuf.recv_utime);
      last_msg_wall = replay::wallUtimeNow();
      if (lcmlog) {
        lcm::LogEvent ev;
        ev.eventnum = 0;
        ev.timestamp = rbuf.recv_utime;
        ev.channel = ch;
        ev.datalen = static_cast<int32_t>(rbuf.data_size);
        ev.data = rbuf.data;
        if (lcmlog->writeEvent(&ev) != 0) node.diagnostics().report("lcmlog:write_error", "lcmlog write failed");
      }
    });
    node.subscribe<PoseEstimate>(channels::kPose, [&](const PoseEstimate& e) { recorder.onPose(e); });
    node.subscribe<std::vector<AnchorEstimate>>(channels::kAnchors,
                                                [&](const std::vector<AnchorEstimate>& a) { recorder.onAnchors(a); });
    node.subscribe<AnchorInit>(channels::kAnchorInit, [&](const AnchorInit& a) { recorder.onAnchorInit(a); });
    node.subscribe<PoseSample>(channels::kGroundTruth, [&](const PoseSample& p) { recorder.onGroundTruth(p); });
    node.subscribe<EstimatorStatus>(channels::kEstimatorStatus,
                                    [&](const EstimatorStatus& s) { recorder.onEstimatorStatus(s); });
    node.subscribe<CalibStatus>(channels::kCalibStatus, [&](const CalibStatus& s) { recorder.onCalibStatus(s); });
    node.subscribe<MissionStatus>(channels::kMissionStatus, [&](const MissionStatus& s) { recorder.onMissionStatus(s); });

    const double idle_s = opts.getDouble("exit-when-idle", 0.0);
    const int64_t progress_period_us = 10'000'000;
    int64_t next_progress = replay::wallUtimeNow() + progress_period_us;
    node.setHeartbeat(Duration::fromSec(opts.getDouble("flush-period", 0.5)), [&] {
      recorder.flush();
      const int64_t now = replay::wallUtimeNow();
      if (now >= next_progress) {
        int64_t total = 0;
        for (const auto& [ch, c] : recorder.channels()) total += c.messages;
        spdlog::info("{} messages, {} poses, {} anchor rows so far", total, recorder.posesWritten(),
                     recorder.anchorRowsWritten());
        next_progress = now + progress_period_us;
      }
    });
    spdlog::info("LCM {}; recording into {}{}", node.url(), opts.get("out"),
                 lcmlog ? " and " + opts.get("lcmlog") : std::string());
    const int rc = node.spin([&] {
      return idle_s > 0 && last_msg_wall > 0 && replay::wallUtimeNow() - last_msg_wall > idle_s * 1e6;
    });
    recorder.finish(node.diagnostics());
    lcmlog.reset();
    spdlog::info("{}", recorder.summaryText());
    if (node.diagnostics().total() > 0) spdlog::warn("counters: {}", node.diagnostics().summary());
    return rc;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
