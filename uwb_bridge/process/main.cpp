/// uwb_bridge: ranges onto RANGE, from a dataset folder, from range CSV files (the published
/// format, e.g. a real recording with one file per device), or live from the serial line output of
/// the UWB TWR firmware driver (see --help).
#include <spdlog/spdlog.h>

#include <filesystem>
#include <set>
#include <sstream>

#include "common/cli.h"
#include "common/setup.h"
#include "transport/channels.h"
#include "transport/lcm_node.h"
#include "transport/process_options.h"
#include "transport/replay/clock.h"
#include "transport/replay_runner.h"
#include "uwb_bridge/line_reader.h"
#include "uwb_bridge/range_csv_import.h"
#include "uwb_bridge/serial_line_parser.h"

namespace {

using namespace meshnav;

const std::string kUsage = std::string(
    "uwb_bridge (--dataset DIR | --csv FILE[,FILE...] [FILE...] | --serial DEV|-) [options]\n"
    "  Publishes UWB ranges on RANGE (message utime = range time).\n"
    "  --dataset DIR      replay ranges.csv of a dataset folder\n"
    "  --csv FILES        replay range CSV files in the published format (t,range_raw,range_corr,R,\n"
    "                     UWB_ID1,UWB_ID2,type_ID1,type_ID2,LOS; types T/A or 84/65), merged and\n"
    "                     time-sorted; more files may follow as arguments\n"
    "  --serial DEV       read the firmware driver's lines 'seq ID1 ID2 range_m' (space or comma\n"
    "                     separated) from a serial device, FIFO, file, or '-' for stdin; each range is\n"
    "                     stamped with the wall time of its receipt; malformed lines are reported\n"
    "                     with their line number and counted\n"
    "  --baud N           serial speed when DEV is a tty (default: leave as is)\n"
    "  --tags ID,ID       (serial) ids that are tags; every other id is an anchor\n"
    "  --setup FILE       (serial) take the tag ids from setup.yaml (rel_tag_positions)\n"
    "  --min-range M      smallest plausible range [m] (default -0.5)\n"
    "  --max-range M      largest plausible range [m] (default 500)\n"
    "  Replays (dataset, csv) exit when played (0); serial ends at end of input (0). Bad input: 1;\n"
    "  --wait-for timeout: 3.\n") +
    transport::kReplayUsage + transport::kProcessUsage;

std::set<SensorId> parseIdList(const std::string& s) {
  std::set<SensorId> ids;
  for (const auto& item : uwb::splitPathList(s)) {
    char* end = nullptr;
    const long v = std::strtol(item.c_str(), &end, 10);
    if (end == item.c_str() || *end != '\0' || v < 0) throw std::runtime_error("--tags: '" + item + "' is not an id");
    ids.insert(static_cast<SensorId>(v));
  }
  return ids;
}

int runSerial(transport::LcmNode& node, const transport::OptionSource& opts, const RangeLimits& limits,
              const transport::ReplayProcessOptions& start) {
  uwb::SerialParserOptions po;
  po.limits = limits;
  if (opts.has("tags")) po.tag_ids = parseIdList(opts.get("tags"));
  if (opts.has("setup"))
    for (const auto& [id, p] : loadSetup(opts.get("setup")).rel_tag_positions) po.tag_ids.insert(id);
  std::ostringstream tags;
  for (auto id : po.tag_ids) tags << id << ' ';
  const std::string dev = opts.get("serial");
  spdlog::info("serial input {}; tags: {}(all other ids are anchors)", dev == "-" ? "stdin" : dev,
               po.tag_ids.empty() ? std::string("none ") : tags.str());
  uwb::LineReader reader(dev, static_cast<int>(opts.getInt("baud", 0)));
  uwb::SerialLineParser parser(po, node.diagnostics(), dev == "-" ? "stdin" : dev);
  if (!transport::waitForStart(node, start)) return node.stopRequested() ? 0 : 3;

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
      const auto r = parser.parse(line, Timestamp::fromUtime(replay::wallUtimeNow()));
      if (r.outcome == uwb::SerialLineParser::Outcome::Range) node.publish(channels::kRange, r.range);
    }
    if (period > 0 && replay::wallUtimeNow() >= next_progress) {
      spdlog::info("{}", progressLine());
      next_progress += period;
    }
  }
  spdlog::info("{}{}", progressLine(),
               node.diagnostics().total() ? "; " + node.diagnostics().summary() : std::string());
  return 0;
}

int runReplay(transport::LcmNode& node, const std::vector<RangeSample>& ranges,
              const transport::ReplayProcessOptions& o) {
  const auto events = replay::mergeTimeline({replay::timesOf(ranges)});
  if (events.empty()) {
    spdlog::error("no valid range to replay");
    return 1;
  }
  spdlog::info("{} ranges to replay ({:.3f} .. {:.3f} s) at {}", ranges.size(), ranges.front().t.sec(),
               ranges.back().t.sec(), o.replay.rate > 0 ? fmt::format("{:g}x", o.replay.rate) : "max speed");
  if (!transport::waitForStart(node, o)) return node.stopRequested() ? 0 : 3;
  int64_t n = 0;
  transport::runReplay(o, events, [&](const replay::ReplayEvent& ev) {
    node.publish(channels::kRange, ranges[ev.index]);
    ++n;
  });
  spdlog::info("published RANGE {}", n);
  return node.diagnostics().get("lcm:publish_error") > 0 ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  Cli cli("uwb_bridge", kUsage);
  std::vector<std::string> names = {"dataset", "csv", "serial", "baud", "tags", "setup", "min-range", "max-range",
                                    "lcm-url", "log-level"};
  for (const auto& n : names) cli.option(n);
  transport::declareProcessOptions(cli);
  transport::declareReplayOptions(cli);
  names.insert(names.end(), transport::replayOptionNames().begin(), transport::replayOptionNames().end());
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  transport::startProcess("uwb_bridge", cli);
  try {
    const transport::OptionSource opts(cli, names);
    std::vector<std::string> csv_files;
    if (opts.has("csv")) csv_files = uwb::splitPathList(opts.get("csv"));
    for (const auto& p : cli.positional()) csv_files.push_back(p);
    const int modes = (opts.has("dataset") ? 1 : 0) + (csv_files.empty() ? 0 : 1) + (opts.has("serial") ? 1 : 0);
    if (modes != 1) {
      spdlog::error("give exactly one of --dataset, --csv, --serial\n{}", kUsage);
      return 2;
    }
    RangeLimits limits;
    limits.min_m = opts.getDouble("min-range", limits.min_m);
    limits.max_m = opts.getDouble("max-range", limits.max_m);
    const auto replay_options = transport::replayOptionsFrom(opts);

    if (opts.has("serial")) {
      transport::LcmNode node("uwb_bridge", opts.get("lcm-url"));
      return runSerial(node, opts, limits, replay_options);
    }
    Diagnostics diag;
    std::vector<RangeSample> ranges;
    if (opts.has("dataset")) {
      ranges = uwb::importRangeCsv({(std::filesystem::path(opts.get("dataset")) / "ranges.csv").string()}, diag, limits);
    } else {
      ranges = uwb::importRangeCsv(csv_files, diag, limits);
    }
    if (diag.total() > 0) spdlog::warn("input problems (rows dropped): {}", diag.summary());
    transport::LcmNode node("uwb_bridge", opts.get("lcm-url"));
    spdlog::info("LCM {}", node.url());
    return runReplay(node, ranges, replay_options);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
