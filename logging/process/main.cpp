/// logging: records the system's channels into the run files (estimate.csv, anchors.csv,
/// anchor_init.yaml, groundtruth.csv, summary.yaml) and optionally every message into an .lcmlog.
#include <lcm/lcm-cpp.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>

#include "common/dir_lock.h"
#include "logging/run_recorder.h"
#include "logging/torn_tail.h"
#include "transport/channels.h"
#include "transport/process_main.h"

namespace {

using namespace meshnav;

/// The --lcmlog file opened for writing (its folder created); throws naming it when it cannot be.
/// `append`: continued, after cutting an event the killed logger left half written (counted as
/// "lcmlog:torn_event_cut"): LCM's reader would stop there and lose every event appended after.
std::unique_ptr<lcm::LogFile> openLcmLog(const std::string& path, bool append, Diagnostics& diag) {
  const std::filesystem::path p(path);
  if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
  if (const int64_t cut = append ? logging::cutTornLcmLogEvent(path) : 0; cut > 0)
    diag.report("lcmlog:torn_event_cut", fmt::format("{}: cut a half-written last event of {} bytes (the previous "
                                                     "logger was killed while writing it)",
                                                     path, cut));
  auto log = std::make_unique<lcm::LogFile>(p.string(), append ? "a" : "w");
  if (!log->good()) throw std::runtime_error(p.string() + ": cannot open for writing");
  return log;
}

/// The process's own options (--lcm-url, --log-level come from transport::ProcessMain).
struct LoggingOptions {
  std::string out, lcmlog_path, channel_regex = ".*", run_id;
  double flush_period_s = 0.5, idle_s = 0.0;
};

void declareOptions(Cli& cli, LoggingOptions& o) {
  cli.optional("out", o.out, "output folder (created); required")->type_name("DIR");
  cli.optional("lcmlog", o.lcmlog_path, "also write every message of --channels into an LCM log (lcm-logplayer)")
      ->type_name("FILE");
  cli.option("channels", o.channel_regex, "channels recorded into --lcmlog and counted")->type_name("REGEX");
  cli.option("flush-period", o.flush_period_s, "seconds between flushes of the CSV files and the --lcmlog")
      ->type_name("S")
      ->check(cli::positive());
  cli.optional("exit-when-idle", o.idle_s,
               "exit once nothing arrived for S seconds after the first message (e.g. after an lcm-logplayer replay; "
               "default: run until stopped)")
      ->type_name("S")
      ->check(cli::nonNegative());
  cli.optional("run-id", o.run_id,
               "id of the run (launch files: ${T0_UTIME}); kept in OUT/.logging_run_id: a logger restarted with the "
               "id already there continues the files of its run instead of starting them anew")
      ->type_name("ID");
  cli.optionsFile("these options as a YAML map (`flush_period: 1`); the command line wins");
}

/// Whether this is a restart within the same run (the supervisor respawned us): --run-id equals the
/// id kept in `id_file`; then the files are continued.
bool continuesRun(const std::filesystem::path& id_file, const std::string& run_id, const std::string& out) {
  if (run_id.empty()) return false;
  std::string previous;
  if (std::ifstream in(id_file); in) std::getline(in, previous);
  const bool append = previous == run_id;
  if (append) spdlog::warn("restart within run {}: continuing the files in {}", run_id, out);
  return append;
}

/// The typed channels the run files are made of.
void subscribeRunFiles(transport::LcmNode& node, logging::RunRecorder& recorder) {
  node.subscribe(channels::kPose, [&](const PoseEstimate& e) { recorder.onPose(e); });
  node.subscribe(channels::kPoseSmoothed, [&](const PoseEstimate& e) { recorder.onPoseSmoothed(e); });
  node.subscribe(channels::kAnchors, [&](const std::vector<AnchorEstimate>& a) { recorder.onAnchors(a); });
  node.subscribe(channels::kAnchorInit, [&](const AnchorInit& a) { recorder.onAnchorInit(a); });
  node.subscribe(channels::kGroundTruth, [&](const PoseSample& p) { recorder.onGroundTruth(p); });
  node.subscribe(channels::kEstimatorStatus, [&](const EstimatorStatus& s) { recorder.onEstimatorStatus(s); });
  node.subscribe(channels::kCalibStatus, [&](const CalibStatus& s) { recorder.onCalibStatus(s); });
  node.subscribe(channels::kMissionStatus, [&](const MissionStatus& s) { recorder.onMissionStatus(s); });
}

/// Flushes the files every `period_s` of wall time (a kill -9 loses at most one period), with a
/// progress line every 10 s.
/// The --lcmlog's writes: a failed write or flush is reported once with the file, and the logger
/// exits 1 at the end naming what is lost (events after the last flush that succeeded).
struct LcmLogWrites {
  std::string path;
  int64_t events = 0, bytes = 0;            ///< handed to the log
  int64_t kept_events = 0, kept_bytes = 0;  ///< at the last successful flush
  int failed_errno = -1;                    ///< errno of the first failure (-1: none)

  void wrote(int64_t n) {
    ++events;
    bytes += n;
  }
  void fail(Diagnostics& diag, int err) {
    if (failed_errno < 0) {
      failed_errno = err;
      diag.report("lcmlog:write_error", fmt::format("{}: write failed ({}); events from now on are lost", path,
                                                    err ? std::strerror(err) : "stream error"));
    } else {
      diag.count("lcmlog:write_error");
    }
  }
  void flush(lcm::LogFile* log, Diagnostics& diag) {
    if (!log || failed_errno >= 0) return;
    errno = 0;
    if (std::fflush(log->getFilePtr()) != 0 || std::ferror(log->getFilePtr())) return fail(diag, errno);
    kept_events = events;
    kept_bytes = bytes;
  }
  /// "" when every event is in the file, else the error for the end of the run.
  std::string lost() const {
    if (failed_errno < 0) return "";
    return fmt::format("{}: write failed ({}; {} of {} events, {} bytes, written since the last flush that "
                       "succeeded are lost or torn)",
                       path, failed_errno ? std::strerror(failed_errno) : "stream error", events - kept_events,
                       events, bytes - kept_bytes);
  }
};

void flushPeriodically(transport::LcmNode& node, logging::RunRecorder& recorder, lcm::LogFile* lcmlog,
                       LcmLogWrites& writes, double period_s) {
  const int64_t progress_period_us = 10'000'000;
  node.setHeartbeat(Duration::fromSec(period_s),
                    [&node, &recorder, lcmlog, &writes, progress_period_us,
                     next_progress = replay::wallUtimeNow() + progress_period_us]() mutable {
                      writes.flush(lcmlog, node.diagnostics());
                      recorder.flush();
                      const int64_t now = replay::wallUtimeNow();
                      if (now < next_progress) return;
                      int64_t total = 0;
                      for (const auto& [ch, c] : recorder.channels()) total += c.messages;
                      spdlog::info("{} messages, {} poses, {} anchor rows so far", total, recorder.posesWritten(),
                                   recorder.anchorRowsWritten());
                      next_progress = now + progress_period_us;
                    });
}

}  // namespace

int main(int argc, char** argv) {
  transport::ProcessMain process(
      "logging",
      "Subscribes to every channel. Writes into --out: estimate.csv (POSE), anchors.csv (ANCHORS), anchor_init.yaml "
      "(ANCHOR_INIT), groundtruth.csv (GROUND_TRUTH), and on exit summary.yaml (messages per channel, last "
      "ESTIMATOR_STATUS / CALIB_STATUS / MISSION_STATUS, counters). Files (CSVs and --lcmlog) are flushed every "
      "--flush-period of wall time and on SIGINT/SIGTERM: a stop loses nothing received, a kill -9 at most the last "
      "period. A logger restarted with the same --run-id cuts the half-written last row or event a kill left, then "
      "continues the files.");
  return process.run<LoggingOptions>(argc, argv, declareOptions, [&](LoggingOptions& o) {
    process.require(!o.out.empty(), "out");
    // The folder's files are this logger's alone: a second logger into it is refused (exit 7).
    const DirLock out_lock(o.out, "--out");
    const std::filesystem::path id_file = std::filesystem::path(o.out) / ".logging_run_id";
    const bool append = continuesRun(id_file, o.run_id, o.out);
    logging::RunRecorder recorder(o.out, append);
    if (!o.run_id.empty()) std::ofstream(id_file) << o.run_id << "\n";
    transport::LcmNode& node = process.lcm();
    std::unique_ptr<lcm::LogFile> lcmlog =
        o.lcmlog_path.empty() ? nullptr : openLcmLog(o.lcmlog_path, append, node.diagnostics());
    LcmLogWrites writes{o.lcmlog_path};
    int64_t last_msg_wall = 0;
    node.subscribeRaw(o.channel_regex, [&](const lcm::ReceiveBuffer& rbuf, const std::string& ch) {
      if (ch == "LCM_SELF_TEST") return;  // udpm's own start-up probe
      recorder.countMessage(ch, rbuf.data_size, rbuf.recv_utime);
      last_msg_wall = replay::wallUtimeNow();
      if (!lcmlog) return;
      lcm::LogEvent ev{0, rbuf.recv_utime, ch, static_cast<int32_t>(rbuf.data_size), rbuf.data};
      writes.wrote(static_cast<int64_t>(rbuf.data_size));
      errno = 0;
      if (lcmlog->writeEvent(&ev) != 0) writes.fail(node.diagnostics(), errno);
    });
    subscribeRunFiles(node, recorder);
    flushPeriodically(node, recorder, lcmlog.get(), writes, o.flush_period_s);
    spdlog::info("LCM {}; recording into {}{}", node.url(), o.out, lcmlog ? " and " + o.lcmlog_path : std::string());
    const int rc = node.spin([&] {
      return o.idle_s > 0 && last_msg_wall > 0 && replay::wallUtimeNow() - last_msg_wall > o.idle_s * 1e6;
    });
    writes.flush(lcmlog.get(), node.diagnostics());
    recorder.finish(node.diagnostics());
    lcmlog.reset();
    spdlog::info("{}", recorder.summaryText());
    if (node.diagnostics().total() > 0) spdlog::warn("counters: {}", node.diagnostics().summary());
    if (recorder.diagnostics().total() > 0) spdlog::warn("recorder: {}", recorder.diagnostics().summary());
    if (const std::string lost = writes.lost(); !lost.empty()) {
      spdlog::error("{}", lost);
      return 1;
    }
    return rc;
  });
}
