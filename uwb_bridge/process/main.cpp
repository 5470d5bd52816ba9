/// uwb_bridge: ranges onto RANGE, from a dataset folder, from range CSV files (the published
/// format, e.g. a real recording with one file per device), or live from the serial line output of
/// the UWB TWR firmware driver (see --help).
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <set>
#include <sstream>

#include "common/setup.h"
#include "transport/channels.h"
#include "transport/lcm_node.h"
#include "transport/process_main.h"
#include "transport/replay/clock.h"
#include "transport/replay_runner.h"
#include "transport/time_sync.h"
#include "uwb_bridge/line_reader.h"
#include "uwb_bridge/range_csv_import.h"
#include "uwb_bridge/serial_line_parser.h"

namespace {

using namespace meshnav;

/// The command line of the bridge.
struct UwbBridgeOptions {
  std::string dataset, csv, serial, setup;
  std::vector<std::string> files;  ///< more range CSV files (positional)
  int baud = 0;
  std::vector<SensorId> tags;
  std::vector<SensorId> initiators;  ///< publish only ranges these devices initiated (empty: all)
  RangeLimits limits;
  double clock_offset_s = 0.0;  ///< fault injection: this host's clock is off by this much [s]
  bool time_sync = false;       ///< stamp in the estimator host's clock (TIME_SYNC exchanges)
  transport::ReplayCliValues replay;
};

void declareOptions(Cli& cli, UwbBridgeOptions& o) {
  cli.optional("dataset", o.dataset, "replay ranges.csv of a dataset folder")->type_name("DIR");
  cli.optional("csv", o.csv,
               "replay range CSV files in the published format (t,range_raw,range_corr,R,UWB_ID1,UWB_ID2,type_ID1,"
               "type_ID2,LOS; types T/A or 84/65), merged and time-sorted; more files may follow as arguments")
      ->type_name("FILE[,FILE...]");
  cli.app().add_option("files", o.files, "more range CSV files (with --csv)")->type_name("FILE");
  cli.optional("serial", o.serial,
               "read the firmware driver's lines 'seq ID1 ID2 range_m' (space or comma separated) from a serial "
               "device, FIFO, file, or '-' for stdin; each range is stamped with the wall time of its receipt; "
               "malformed lines are reported with their line number and counted")
      ->type_name("DEV");
  cli.optional("baud", o.baud, "serial speed when DEV is a tty (default: leave as is)")
      ->type_name("N")
      ->check(CLI::NonNegativeNumber);
  cli.idList("tags", o.tags, "(serial) ids that are tags; every other id is an anchor");
  cli.idList("initiators", o.initiators,
             "publish only the ranges these devices initiated (UWB_ID1), as the computer of one anchor does in a "
             "multi-host deployment (config/launch/multihost.yaml); default: every range");
  cli.optional("setup", o.setup, "(serial) take the tag ids from setup.yaml (rel_tag_positions)")->type_name("FILE");
  cli.option("min-range", o.limits.min_m, "smallest plausible range [m]")->type_name("M")->check(cli::finite());
  cli.option("max-range", o.limits.max_m, "largest plausible range [m]")->type_name("M")->check(cli::finite());
  cli.option("clock-offset", o.clock_offset_s,
             "fault injection: act as a host whose clock is off by S seconds (every stamp and TIME_SYNC reading "
             "moved by S; tests of time across hosts, docs/deployment.md)")
      ->type_name("S")
      ->check(cli::finite());
  cli.option("time-sync", o.time_sync,
             "estimate this host's clock offset to the estimator's host by TIME_SYNC exchanges (at start and every "
             "second) and publish ranges stamped in its clock (for bridges on other hosts than the estimator)")
      ->type_name("0|1");
  transport::declareReplayOptions(cli, o.replay);
  cli.optionsFile("these options as a YAML map (`rate: 10`, `max_range: 100`); the command line wins");
}

/// The host clock as this bridge sees it (--clock-offset), and its offset to the estimator's host
/// (--time-sync): every stamp goes out in the reference clock once the offset is known.
class BridgeClock {
 public:
  BridgeClock(transport::LcmNode& node, const UwbBridgeOptions& o)
      : injected_(Duration::fromSec(o.clock_offset_s)) {
    if (o.time_sync) {
      std::string client = "uwb_bridge";
      for (auto id : o.initiators) client += " " + std::to_string(id);
      client += " pid " + std::to_string(::getpid());
      sync_.emplace(node, client, injected_);
    }
    if (injected_.us != 0)
      spdlog::warn("--clock-offset: acting as a host whose clock is off by {:+.3f} s", injected_.sec());
  }
  /// Before the data starts: a first offset estimate (5 exchanges within at most 3 s).
  void start() {
    if (!sync_) return;
    if (!sync_->synchronize(5, Duration::fromSec(0.05), Duration::fromSec(3.0)))
      spdlog::warn("time sync: no TIME_SYNC reply within 3 s; stamps stay in this host's clock until one comes");
  }
  /// Between messages: a new exchange every second.
  void poll(transport::LcmNode& node) {
    if (!sync_) return;
    while (node.spinOnce(0) > 0) {
    }
    sync_->poll(Duration::fromSec(1.0));
  }
  /// A stamp of the true time `t` as this host writes it, in the reference clock when known.
  Timestamp stamp(Timestamp t) {
    const Timestamp local{t.us + injected_.us};
    return sync_ ? sync_->toReference(local) : local;
  }
  std::string summary() const {
    if (!sync_) return "";
    if (!sync_->offset()) return "time sync: no reply";
    return fmt::format("time sync: offset {:+.1f} ms (± {:.1f} ms) from {} replies", *sync_->offset() / 1e3,
                       *sync_->errorBound() / 1e3, sync_->replies());
  }

 private:
  Duration injected_;
  std::optional<transport::TimeSyncClient> sync_;
};

int runSerial(transport::LcmNode& node, const UwbBridgeOptions& opts, const transport::ReplayProcessOptions& start) {
  uwb::SerialParserOptions po;
  po.limits = opts.limits;
  po.tag_ids.insert(opts.tags.begin(), opts.tags.end());
  if (!opts.setup.empty())
    for (const auto& [id, p] : loadSetup(opts.setup).rel_tag_positions) po.tag_ids.insert(id);
  std::ostringstream tags;
  for (auto id : po.tag_ids) tags << id << ' ';
  const std::string& dev = opts.serial;
  spdlog::info("serial input {}; tags: {}(all other ids are anchors)", dev == "-" ? "stdin" : dev,
               po.tag_ids.empty() ? std::string("none ") : tags.str());
  uwb::LineReader reader(dev, opts.baud);
  uwb::SerialLineParser parser(po, node.diagnostics(), dev == "-" ? "stdin" : dev);
  BridgeClock clock(node, opts);
  if (!transport::waitForStart(node, start)) return node.stopRequested() ? 0 : 3;
  clock.start();

  const int64_t period = start.replay.progress_period.us;
  int64_t next_progress = replay::wallUtimeNow() + period;
  auto progressLine = [&] {
    return fmt::format("serial: {} lines, {} ranges published, {} malformed, {} lost (seq gaps)",
                       parser.linesSeen(), parser.rangesParsed(), parser.malformed(), parser.seqGaps());
  };
  std::string line;
  while (!node.stopRequested()) {
    const auto st = reader.readLine(line, 100);
    if (st == uwb::LineReader::Status::Eof) break;
    if (st == uwb::LineReader::Status::Error) {
      spdlog::error("{}: read error", dev);
      return 1;
    }
    if (st == uwb::LineReader::Status::Line) {
      auto r = parser.parse(line, clock.stamp(Timestamp::fromUtime(replay::wallUtimeNow())));
      if (r.outcome == uwb::SerialLineParser::Outcome::Range &&
          (opts.initiators.empty() ||
           std::find(opts.initiators.begin(), opts.initiators.end(), r.range.id_initiator) != opts.initiators.end()))
        node.publish(channels::kRange, r.range);
    }
    clock.poll(node);
    if (period > 0 && replay::wallUtimeNow() >= next_progress) {
      spdlog::info("{}", progressLine());
      next_progress += period;
    }
  }
  spdlog::info("{}{}{}", progressLine(),
               node.diagnostics().total() ? "; " + node.diagnostics().summary() : std::string(),
               clock.summary().empty() ? "" : "; " + clock.summary());
  return 0;
}

int runReplay(transport::LcmNode& node, std::vector<RangeSample> ranges, const UwbBridgeOptions& opts,
              const transport::ReplayProcessOptions& o) {
  const auto events = replay::mergeTimeline({replay::timesOf(ranges)});
  if (events.empty()) {
    spdlog::error("no valid range to replay");
    return 1;
  }
  spdlog::info("{} ranges to replay ({:.3f} .. {:.3f} s) at {}", ranges.size(), ranges.front().t.sec(),
               ranges.back().t.sec(), o.replay.rate > 0 ? fmt::format("{:g}x", o.replay.rate) : "max speed");
  BridgeClock clock(node, opts);
  if (!transport::waitForStart(node, o)) return node.stopRequested() ? 0 : 3;
  clock.start();
  int64_t n = 0;
  transport::runReplay(o, events, [&](const replay::ReplayEvent& ev) {
    RangeSample r = ranges[ev.index];
    r.t = clock.stamp(r.t);
    node.publish(channels::kRange, r);
    ++n;
    clock.poll(node);
  });
  spdlog::info("published RANGE {}{}", n, clock.summary().empty() ? "" : "; " + clock.summary());
  return node.diagnostics().get("lcm:publish_error") > 0 ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  transport::ProcessMain process(
      "uwb_bridge",
      "Publishes UWB ranges on RANGE (message utime = range time), from a dataset folder (--dataset), range CSV "
      "files (--csv) or the serial line output of the UWB TWR firmware driver (--serial); give exactly one. Replays "
      "exit when played (0); serial ends at end of input (0). Bad input: 1; --wait-for timeout: 3.");
  return process.run<UwbBridgeOptions>(argc, argv, declareOptions, [&](UwbBridgeOptions& opts) {
    std::vector<std::string> csv_files;
    if (!opts.csv.empty()) csv_files = uwb::splitPathList(opts.csv);
    csv_files.insert(csv_files.end(), opts.files.begin(), opts.files.end());
    const int modes = (opts.dataset.empty() ? 0 : 1) + (csv_files.empty() ? 0 : 1) + (opts.serial.empty() ? 0 : 1);
    if (modes != 1) {
      spdlog::error("give exactly one of --dataset, --csv, --serial (see --help)");
      return 2;
    }
    const auto replay_options = transport::replayOptionsFrom(process.cli(), opts.replay);
    if (!opts.serial.empty()) return runSerial(process.lcm(), opts, replay_options);
    Diagnostics diag;
    if (!opts.dataset.empty()) csv_files = {(std::filesystem::path(opts.dataset) / "ranges.csv").string()};
    std::vector<RangeSample> ranges = uwb::importRangeCsv(csv_files, diag, opts.limits);
    if (diag.total() > 0) spdlog::warn("input problems (rows dropped): {}", diag.summary());
    if (!opts.initiators.empty()) {
      const size_t removed =
          uwb::keepInitiators(ranges, std::set<SensorId>(opts.initiators.begin(), opts.initiators.end()));
      spdlog::info("--initiators: {} ranges initiated by other devices left out, {} kept", removed, ranges.size());
    }
    spdlog::info("LCM {}", process.lcm().url());
    return runReplay(process.lcm(), std::move(ranges), opts, replay_options);
  });
}
