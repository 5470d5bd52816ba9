/// dataset_to_lcmlog: writes every measurement of a dataset folder (docs/formats.md) into an LCM log,
/// time-sorted, with event timestamps = data utime, so that `lcm-logplayer FILE` replays the
/// sequence into a running system (IMU, BARO, FLIGHT_STATE, RANGE and GROUND_TRUTH).
#include <lcm/lcm-cpp.hpp>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <vector>

#include "common/cli_main.h"
#include "common/dataset.h"
#include "transport/channels.h"
#include "transport/convert.h"
#include "transport/replay/replay_event.h"

namespace {

/// The sender_id of every message of a dataset log: one fixed id (the log is one publisher,
/// lcm-logplayer, to the receivers' PublisherWatch, transport/publisher_watch.h), so that the same
/// dataset gives the same log byte for byte. Its time bits say 1970: older than any process.
constexpr int64_t kDatasetLogSenderId = 0x10617;

template <class T>
bool writeEvent(lcm::LogFile& log, meshnav::channels::Channel<T> channel, const std::string& prefix, int64_t utime,
                const std::type_identity_t<T>& value, std::vector<uint8_t>& buf) {
  auto msg = meshnav::transport::toWire(value);
  msg.sender_id = kDatasetLogSenderId;
  const int n = msg.getEncodedSize();
  buf.resize(static_cast<size_t>(n));
  if (msg.encode(buf.data(), 0, n) != n) return false;
  lcm::LogEvent ev;
  ev.eventnum = 0;
  ev.timestamp = utime;
  ev.channel = meshnav::channels::prefixed(channel, prefix);
  ev.datalen = n;
  ev.data = buf.data();
  return log.writeEvent(&ev) == 0;
}

/// The streams of the log, numbered in their order at equal times: the estimator's canonical
/// order (estimator/node/estimator_input.h: flight state, IMU, baro, range, then height), so a
/// replay of the log causes no rewinds; the ground truth after the inputs of its instant. An
/// explicit table (test_dataset_to_lcmlog.cpp checks the order in a written log).
enum Stream : int {
  kFlightStateStream = 0,
  kImuStream = 1,
  kBaroStream = 2,
  kRangeStream = 3,
  kGroundTruthStream = 4,
  kHeightStream = 5,
  kStreamCount = 6
};

constexpr char kDescription[] =
    "Writes imu.csv, baro.csv, flight_state.csv, ranges.csv and groundtruth.csv of a dataset folder as the channels "
    "IMU, BARO, FLIGHT_STATE, RANGE, GROUND_TRUTH into an LCM log (event time = data time), ready for "
    "`lcm-logplayer FILE.lcmlog`.";

struct Options {
  std::string dataset, out, channel_prefix;
  bool no_ground_truth = false;
};

void declareOptions(meshnav::Cli& cli, Options& o) {
  cli.optional("dataset", o.dataset, "dataset folder (setup.yaml and ranges.csv required)")->type_name("DIR")->required();
  cli.optional("out", o.out, "output log file (overwritten)")->type_name("FILE")->required();
  cli.flag("no-ground-truth", o.no_ground_truth, "leave GROUND_TRUTH out");
  cli.optional("channel-prefix", o.channel_prefix,
               "the channels of vehicle P of a fleet: P/IMU, P/RANGE, ... (docs/channels.md, \"Vehicle prefixes\")")
      ->type_name("P")
      ->check(CLI::Validator([](std::string& p) { return meshnav::channels::prefixProblem(p); }, "", "vehicle prefix"));
}

/// The work of main: the dataset's streams merged in time order and written as one log.
int writeLog(const Options& o) {
  using namespace meshnav;
  Diagnostics diag;
  const Dataset ds = readDataset(o.dataset, diag);
  const bool with_gt = !o.no_ground_truth;
  // Equal times keep the order of the streams (Stream).
  std::vector<std::vector<Timestamp>> times(kStreamCount);
  times[kFlightStateStream] = replay::timesOf(ds.flight_states);
  times[kImuStream] = replay::timesOf(ds.imu);
  times[kBaroStream] = replay::timesOf(ds.baro);
  times[kRangeStream] = replay::timesOf(ds.ranges);
  if (with_gt) times[kGroundTruthStream] = replay::timesOf(ds.ground_truth);
  times[kHeightStream] = replay::timesOf(ds.heights);
  const auto events = replay::mergeTimeline(times);

  const std::filesystem::path outp(o.out);
  if (outp.has_parent_path()) std::filesystem::create_directories(outp.parent_path());
  lcm::LogFile log(o.out, "w");
  if (!log.good()) {
    spdlog::error("{}: cannot open for writing", o.out);
    return 1;
  }
  std::vector<uint8_t> buf;
  size_t written = 0;
  for (const auto& ev : events) {
    bool ok = false;
    switch (ev.stream) {
      case kFlightStateStream: ok = writeEvent(log, channels::kFlightState, o.channel_prefix, ev.t.us, ds.flight_states[ev.index], buf); break;
      case kImuStream: ok = writeEvent(log, channels::kImu, o.channel_prefix, ev.t.us, ds.imu[ev.index], buf); break;
      case kBaroStream: ok = writeEvent(log, channels::kBaro, o.channel_prefix, ev.t.us, ds.baro[ev.index], buf); break;
      case kRangeStream: ok = writeEvent(log, channels::kRange, o.channel_prefix, ev.t.us, ds.ranges[ev.index], buf); break;
      case kGroundTruthStream: ok = writeEvent(log, channels::kGroundTruth, o.channel_prefix, ev.t.us, ds.ground_truth[ev.index], buf); break;
      case kHeightStream: ok = writeEvent(log, channels::kHeight, o.channel_prefix, ev.t.us, ds.heights[ev.index], buf); break;
      default: break;
    }
    if (!ok) {
      spdlog::error("{}: write failed after {} events", o.out, written);
      return 1;
    }
    ++written;
  }
  spdlog::info("{}: {} events (IMU {}, BARO {}, FLIGHT_STATE {}, RANGE {}, GROUND_TRUTH {}, HEIGHT {}), {:.3f}..{:.3f} s",
               o.out, written, ds.imu.size(), ds.baro.size(), ds.flight_states.size(), ds.ranges.size(),
               with_gt ? ds.ground_truth.size() : 0, ds.heights.size(), events.empty() ? 0.0 : events.front().t.sec(),
               events.empty() ? 0.0 : events.back().t.sec());
  if (diag.total() > 0) spdlog::warn("dataset input problems: {}", diag.summary());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return meshnav::cliMain<Options>(argc, argv, "dataset_to_lcmlog", kDescription, declareOptions,
                                   [](const meshnav::Cli&, Options& o) { return writeLog(o); });
}
