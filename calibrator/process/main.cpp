/// calibrator: the CalibratorNode (calibrator/node/calibrator_node.h) on LCM.
///   RANGE, POSE, ANCHORS, CALIB_CMD -> ANCHOR_INIT, CALIB_STATUS.
/// CALIB_STATUS goes out at the node's data-time rate, after every Calibrate command and, as the
/// process heartbeat, every --heartbeat seconds of wall time (also while no data flows).
/// With --fleet it serves every vehicle of a fleet file: vehicle k's P/RANGE, P/POSE, P/ANCHORS in
/// and its own P/ANCHOR_INIT out on its bus (one LCM instance per bus, --bus), CALIB_CMD and
/// CALIB_STATUS on the first vehicle's bus; what it hears and says to each vehicle is
/// pipeline::FleetCalibratorFeed's, as in meshnav_run --fleet.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <iostream>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "calibrator/node/calibrator_node.h"
#include "calibrator/process/calibrator_process_config.h"
#include "common/dir_lock.h"
#include "common/setup.h"
#include "pipeline/fleet.h"
#include "pipeline/fleet_calibrator_feed.h"
#include "transport/channels.h"
#include "transport/fleet_bus.h"
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

/// One vehicle the calibrator serves: where its channels are.
struct VehicleLink {
  VehicleLink(std::string name_, std::string prefix_, transport::LcmNode* lcm_)
      : name(std::move(name_)), prefix(std::move(prefix_)), lcm(lcm_) {}
  std::string name;    ///< the fleet's vehicle name ("" for a calibrator of one vehicle): its journal prefix
  std::string prefix;  ///< the prefix of its channels on the wire (--fleet: its name; else --channel-prefix)
  transport::LcmNode* lcm = nullptr;  ///< its bus
  std::optional<Timestamp> last_pose;
  std::set<int64_t> awaiting_smoothed;  ///< µs of the POSEs taken whose smoothed twin has not come (--smoothed-poses)
};

/// The vehicles of --fleet, or the one of --setup.
struct Served {
  std::vector<pipeline::Vehicle> vehicles;
  SystemSetup setup;  ///< what the calibrator knows (a fleet's: mergeFleetSetups)
};

Served loadServed(const calib::CalibratorProcessConfig& config) {
  Served s;
  if (config.fleet_path.empty()) {
    s.setup = loadSetup(config.setup_path);
    s.vehicles.push_back({"", s.setup});
    return s;
  }
  s.vehicles = pipeline::loadFleetVehicles(config.fleet_path);
  s.setup = pipeline::mergeFleetSetups(s.vehicles, config.fleet_path);
  return s;
}

/// The CalibratorNode wired to LCM: its inputs journaled before they reach it, its outputs
/// published (except while the journal of a restart is replayed), the results file kept up to date.
class CalibratorProcess {
 public:
  /// `links[k]` is where vehicle k of `served` talks; links[0]'s bus is the process's own
  /// (process.lcm(): CALIB_CMD, CALIB_STATUS).
  CalibratorProcess(transport::ProcessMain& process, const calib::CalibratorProcessConfig& config,
                    const Served& served, std::vector<VehicleLink> links)
      : process_(process),
        lcm_(process.lcm()),
        config_(config),
        links_(std::move(links)),
        feed_(served.vehicles, served.setup, lcm_.diagnostics()),
        node_(config.calibrator, served.setup, sinks(), config.node, feed_.vehicleOfTag()),
        results_file_(config.out_yaml),
        pose_period_(Duration::fromSec(config.pose_rate_hz > 0 ? 1.0 / config.pose_rate_hz : 0.0)) {}

  /// With --state-dir: replays the inputs a previous run journaled, then journals the new ones.
  void restoreFromJournal() {
    if (config_.state_dir.empty()) return;
    const std::string path = (std::filesystem::path(config_.state_dir) / "calibrator_inputs.lcmlog").string();
    replaying_ = true;
    Diagnostics& diag = lcm_.diagnostics();
    const int64_t n = transport::InputJournal::read(path, [&](const std::string& wire, const lcm::ReceiveBuffer& rb) {
      const std::string_view ch = channels::unprefixedName(wire);
      const std::string who = wire.size() > ch.size() ? wire.substr(0, wire.size() - ch.size() - 1) : std::string();
      if (ch == channels::kCalibCmd.name) {
        CalibCommand c;
        if (transport::InputJournal::decode(rb, channels::kCalibCmd, c, diag)) onCommand(c);
        return;
      }
      const auto link = std::find_if(links_.begin(), links_.end(), [&](const VehicleLink& l) { return l.name == who; });
      if (link == links_.end()) {
        diag.count("journal_unknown_vehicle");
        return;
      }
      const size_t v = static_cast<size_t>(link - links_.begin());
      if (ch == channels::kAnchorInit.name) {  // an output that was sent: not to be sent again
        AnchorInit sent;
        if (transport::InputJournal::decode(rb, channels::kAnchorInit, sent, diag)) sent_.insert({v, sent.id, sent.t.us});
        return;
      }
      RangeSample r;
      PoseEstimate p;
      std::vector<AnchorEstimate> a;
      if (ch == channels::kRange.name && transport::InputJournal::decode(rb, channels::kRange, r, diag)) onRange(v, r);
      if (ch == channels::kPose.name && transport::InputJournal::decode(rb, channels::kPose, p, diag)) onPose(v, p);
      if (ch == channels::kPoseSmoothed.name && transport::InputJournal::decode(rb, channels::kPoseSmoothed, p, diag))
        onPoseSmoothed(v, p);
      if (ch == channels::kAnchors.name && transport::InputJournal::decode(rb, channels::kAnchors, a, diag))
        onAnchors(v, a);
    });
    replaying_ = false;
    if (n > 0)
      spdlog::warn("restart: {} inputs replayed from {} (data time {} s); anchors: {}", n, path,
                   node_.dataTime() ? formatSeconds(*node_.dataTime()) : std::string("none"),
                   anchorStates(node_.status()));
    journal_ = std::make_unique<transport::InputJournal>(path);
    // A calibration the replay made again whose ANCHOR_INIT the journal does not show as sent to a
    // vehicle (the stop came between the calibration and its publication): sent now. One that was
    // sent is not sent again (an estimator would re-initialize the anchor and lose what it learnt).
    for (const AnchorInit& a : replayed_inits_)
      for (size_t v = 0; v < links_.size(); ++v)
        if (!sent_.count({v, a.id, a.t.us})) {
          spdlog::warn("restart: ANCHOR_INIT {} (t = {} s){} had not been sent before the stop: sent now", a.id,
                       formatSeconds(a.t), links_[v].name.empty() ? std::string() : " to " + links_[v].name);
          lcm_.diagnostics().count("anchor_init_sent_after_restart");
          publishAnchorInit(v, a);
        }
    replayed_inits_.clear();
    sent_.clear();
  }

  /// Subscribes the inputs and starts the CALIB_STATUS heartbeat (with a progress line every 10 s).
  void connect() {
    for (size_t v = 0; v < links_.size(); ++v) {
      transport::LcmNode& bus = *links_[v].lcm;
      const std::string& p = links_[v].prefix;
      bus.subscribeAs(p, channels::kRange, [this, v](const RangeSample& r) { onRange(v, r); });
      bus.subscribeAs(p, channels::kPose, [this, v](const PoseEstimate& pe) { onPose(v, pe); });
      if (config_.smoothed_poses)
        bus.subscribeAs(p, channels::kPoseSmoothed, [this, v](const PoseEstimate& pe) { onPoseSmoothed(v, pe); });
      bus.subscribeAs(p, channels::kAnchors, [this, v](const std::vector<AnchorEstimate>& a) { onAnchors(v, a); });
    }
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

  /// Every bus until a stop.
  int spin() {
    std::vector<transport::LcmNode*> buses;
    for (const VehicleLink& l : links_) buses.push_back(l.lcm);
    return transport::LcmNode::spinAll(buses);
  }

  /// After the loop: the last status, the results file, the counters.
  void finish() {
    const CalibStatus st = process_.stamped(node_.status());
    lcm_.publish(channels::kCalibStatus, st);
    // A second instance (transport/lcm_node.h) leaves the first one's results file alone.
    if (results_file_.enabled() && lcm_.secondInstance().empty()) writeResults(true);
    spdlog::info("stopped at t = {} s; anchors: {}counters: {}", formatSeconds(st.t), anchorStates(st),
                 transport::formatCounters(st.counters));
    // The other buses' handlers (ProcessMain logs its own instance's, the first vehicle's).
    std::set<const transport::LcmNode*> logged = {&lcm_};
    for (const VehicleLink& l : links_)
      if (logged.insert(l.lcm).second && !l.lcm->handlerTimes().empty())
        spdlog::info("time in handlers on {}'s bus: {}", l.name, l.lcm->handlerTimeSummary());
  }

 private:
  calib::CalibratorSinks sinks() {
    calib::CalibratorSinks s;
    s.anchor_init = [this](const AnchorInit& a) {
      logAnchorInit(a);
      if (replaying_) {
        replayed_inits_.push_back(a);
        return;
      }
      for (size_t v = 0; v < links_.size(); ++v) publishAnchorInit(v, a);
    };
    s.status = [this](const CalibStatus& st) {
      if (!replaying_) lcm_.publish(channels::kCalibStatus, process_.stamped(st));
    };
    return s;
  }
  /// ANCHOR_INIT `a` to vehicle v (as it may fuse it), then its record in the journal: what a
  /// restart must not send again.
  void publishAnchorInit(size_t v, const AnchorInit& a) {
    const AnchorInit to_v = feed_.forVehicle(v, a);
    links_[v].lcm->publishAs(links_[v].prefix, channels::kAnchorInit, to_v);
    if (journal_) journal_->writeAs(links_[v].name, channels::kAnchorInit, to_v, a.t.us);
  }
  void writeResults(bool force) {
    const int64_t attempts = node_.diagnostics().get("calibrations_ok") + node_.diagnostics().get("calibrations_refused");
    if (results_file_.update(node_.results(), attempts, force))
      spdlog::info("calibration results written to {}", results_file_.path());
  }
  /// What the node consumes goes to the journal first, so a kill -9 right after loses nothing.
  template <class T>
  void journaled(const std::string& vehicle, channels::Channel<T> channel, const T& value, Timestamp t) {
    if (journal_ && !replaying_) journal_->writeAs(vehicle, channel, value, t.us);
  }
  void onRange(size_t v, const RangeSample& r) {
    if (!feed_.forCalibrator(r)) return;  // the mesh once, not the vehicles' ranges to each other
    journaled(links_[v].name, channels::kRange, r, r.t);
    node_.onRange(r);
    writeResults(false);  // automatic mode calibrates on data
  }
  void onPose(size_t v, const PoseEstimate& p) {
    VehicleLink& l = links_[v];
    if (l.last_pose && p.t >= *l.last_pose && p.t - *l.last_pose < pose_period_) return;  // decimation
    l.last_pose = p.t;
    journaled(l.name, channels::kPose, p, p.t);
    node_.onPose(p, v);
    if (config_.smoothed_poses) l.awaiting_smoothed.insert(p.t.us);
    writeResults(false);
  }
  /// A POSE_SMOOTHED of an instant the node took replaces that pose (the same instant: the newer
  /// wins, CalibratorNode::onPose); others are not needed (decimation).
  void onPoseSmoothed(size_t v, const PoseEstimate& p) {
    std::set<int64_t>& awaiting = links_[v].awaiting_smoothed;
    const auto it = awaiting.find(p.t.us);
    if (it == awaiting.end()) return;
    awaiting.erase(awaiting.begin(), std::next(it));
    journaled(links_[v].name, channels::kPoseSmoothed, p, p.t);
    node_.onPose(p, v);
  }
  void onAnchors(size_t v, const std::vector<AnchorEstimate>& a) {
    journaled(links_[v].name, channels::kAnchors, a, a.empty() ? Timestamp{} : a.front().t);
    node_.onAnchors(feed_.anchorsFrom(v, a));
  }
  void onCommand(const CalibCommand& c) {
    journaled(std::string(), channels::kCalibCmd, c, c.t);
    node_.onCommand(c);
    writeResults(false);
  }

  transport::ProcessMain& process_;
  transport::LcmNode& lcm_;
  const calib::CalibratorProcessConfig& config_;
  bool replaying_ = false;  ///< while the journal is replayed: the results are known to the others
  std::vector<VehicleLink> links_;
  pipeline::FleetCalibratorFeed feed_;
  calib::CalibratorNode node_;
  calib::CalibrationYamlWriter results_file_;
  std::unique_ptr<transport::InputJournal> journal_;
  std::vector<AnchorInit> replayed_inits_;                   ///< the calibrations the replay made again
  std::set<std::tuple<size_t, SensorId, int64_t>> sent_;  ///< (vehicle, anchor, t µs) of the ANCHOR_INITs journaled as sent
  Duration pose_period_;
  int64_t next_progress_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
  transport::ProcessMain process("calibrator", calib::kCalibratorProcessDescription);
  using Config = calib::CalibratorProcessConfig;
  return process.run<Config>(argc, argv, calib::declareCalibratorProcessOptions, [&](Config& config) {
    calib::loadCalibratorProcessConfig(config);
    process.require(!config.setup_path.empty() || !config.fleet_path.empty() || config.print_config, "setup");
    Served served;
    if (!config.setup_path.empty() || !config.fleet_path.empty()) {
      served = loadServed(config);
      calib::applySetup(config, served.setup);
    }
    if (config.print_config) {
      std::cout << config.toString();
      return 0;
    }
    // Its journal is this process's alone: a second calibrator on the folder is refused (exit 7).
    std::optional<DirLock> state_lock;
    if (!config.state_dir.empty()) state_lock.emplace(config.state_dir, "--state-dir");
    // Where each vehicle talks: one vehicle on the process's own bus; a fleet's vehicle k on its bus
    // (the first one's is the process's own, with the fleet's CALIB_CMD and CALIB_STATUS).
    std::vector<VehicleLink> links;
    if (config.fleet_path.empty()) {
      links.emplace_back("", process.channelPrefix(), &process.lcm());
    } else {
      const std::vector<transport::LcmNode*> buses =
          process.fleetBuses(served.vehicles.size(), transport::parseFleetBus(config.bus), "");
      for (size_t k = 0; k < buses.size(); ++k)
        links.emplace_back(served.vehicles[k].name, served.vehicles[k].name, buses[k]);
    }
    CalibratorProcess calibrator(process, config, served, links);
    spdlog::info("calibrator options:\n{}", config.toString());
    calibrator.restoreFromJournal();
    calibrator.connect();
    std::string where;
    for (const VehicleLink& l : links)
      where += (where.empty() ? "" : ", ") + (l.name.empty() ? std::string() : l.name + " on ") + l.lcm->url();
    spdlog::info("LCM {}; {} vehicle(s), {} tags, {} known anchors; {}", where, links.size(),
                 served.setup.rel_tag_positions.size(), served.setup.abs_anchor_positions.size(),
                 config.node.auto_mode ? "automatic calibration" : "calibration on CALIB_CMD");
    const int rc = calibrator.spin();
    calibrator.finish();
    return rc;
  });
}
