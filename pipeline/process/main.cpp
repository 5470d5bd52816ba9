/// peer_router: a fleet's ranges between two vehicles' tags over LCM (docs/fleet.md "Inter-vehicle
/// ranges over LCM"), pipeline::PeerRangeRelay on the vehicles' buses.
///   every vehicle's P/RANGE, P/POSE, P/ANCHOR_INIT -> the receiving vehicle's P/PEER_RANGE.
/// Vehicle k's channels are on its bus (--bus, as the fleet launch's); which vehicle fuses a range
/// and with what is pipeline::PeerRangeFeed's, as in meshnav_run --fleet.
/// With --state-dir the routing's provenance (whose information each vehicle holds) is journaled
/// there every --state-period of data time (pipeline/peer_router_state.h) and taken back by a respawn.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/dir_lock.h"
#include "pipeline/fleet.h"
#include "pipeline/peer_range_relay.h"
#include "pipeline/peer_router_state.h"
#include "transport/channels.h"
#include "transport/fleet_bus.h"
#include "transport/process_main.h"

namespace {

using namespace meshnav;

struct PeerRouterOptions {
  std::string fleet_path, bus = "per-vehicle";
  pipeline::PeerRangeRoutingOptions routing;
  pipeline::PeerRangeRelayOptions relay;
  double progress_s = 10.0;
  std::string state_dir;        ///< the restart journal's folder; empty: none
  double state_period_s = 0.1;  ///< data time between two journal writes [s]
};

/// The journal's file in --state-dir.
std::string statePath(const std::string& dir) { return (std::filesystem::path(dir) / "peer_router_state.yaml").string(); }

void declareOptions(Cli& cli, PeerRouterOptions& o) {
  cli.fleetServing(o.fleet_path, o.bus, "fleet file (docs/formats.md): the vehicles, their datasets' setups; required");
  cli.option("min-anchors", o.routing.min_anchors, "a vehicle ranging fewer distinct anchors than this is short of anchors")
      ->type_name("N")
      ->check(CLI::NonNegativeNumber);
  cli.option("anchor-window", o.routing.anchor_window_s, "data seconds over which a vehicle's anchors are counted")
      ->type_name("S")
      ->check(cli::positive());
  cli.option("memory", o.routing.memory_s, "data seconds a vehicle holds what it received from another")
      ->type_name("S")
      ->check(cli::nonNegative());
  cli.option("max-pose-age", o.relay.max_pose_age_s, "a vehicle's POSE farther than this from a range's instant is not used")
      ->type_name("S")
      ->check(cli::positive());
  cli.option("max-wait", o.relay.max_wait_s,
             "data seconds a range waits for its vehicles' POSE (below the estimators' window_s)")
      ->type_name("S")
      ->check(cli::nonNegative());
  cli.optional("state-dir", o.state_dir,
               "folder of the restart journal (peer_router_state.yaml: whose information each vehicle holds): "
               "written while running, taken back at start")
      ->type_name("DIR");
  cli.option("state-period", o.state_period_s, "data seconds between two writes of the journal")
      ->type_name("S")
      ->check(cli::positive());
  cli.option("progress", o.progress_s, "wall seconds between two progress lines (counters)")->type_name("S")->check(cli::positive());
}

/// The relay wired to each vehicle's bus.
class PeerRouterProcess {
 public:
  PeerRouterProcess(const PeerRouterOptions& o, const std::vector<pipeline::Vehicle>& vehicles, const SystemSetup& fleet_setup,
                    std::vector<transport::LcmNode*> buses, Diagnostics& diag)
      : o_(o), vehicles_(vehicles), buses_(std::move(buses)), relay_(vehicles, fleet_setup, o.routing, o.relay, diag) {
    for (const auto& v : vehicles_) names_.push_back(v.name);
    if (!o_.state_dir.empty()) resume();
  }

  void connect() {
    for (size_t v = 0; v < vehicles_.size(); ++v) {
      transport::LcmNode& bus = *buses_[v];
      const std::string& p = vehicles_[v].name;
      bus.subscribeAs(p, channels::kRange, [this, v](const RangeSample& r) { handled(relay_.onRange(v, r)); });
      bus.subscribeAs(p, channels::kPose, [this, v](const PoseEstimate& pe) { handled(relay_.onPose(v, pe)); });
      // Every vehicle gets each ANCHOR_INIT (the fleet's calibrator); the relay notes an anchor once.
      bus.subscribeAs(p, channels::kAnchorInit, [this](const AnchorInit& a) { relay_.onAnchorInit(a.id); });
    }
  }

  int spin() { return transport::LcmNode::spinAll(buses_); }

  int64_t sent() const { return sent_; }
  size_t held() const { return relay_.held(); }

  /// The journal as of now (with --state-dir; at exit).
  void journal() {
    if (o_.state_dir.empty() || !relay_.dataTime() || relay_.restorePending()) return;
    last_journal_ = *relay_.dataTime();
    try {
      std::filesystem::create_directories(o_.state_dir);
      pipeline::writePeerRouterState(statePath(o_.state_dir), {*relay_.dataTime(), relay_.feed().router().provenance()}, names_);
    } catch (const std::exception& ex) {
      spdlog::error("provenance journal not written: {}", ex.what());
    }
  }

 private:
  /// A journal left in --state-dir (a respawn): taken at the first input (PeerRangeRelay).
  void resume() {
    const std::string path = statePath(o_.state_dir);
    if (!std::filesystem::exists(path)) return;
    try {
      pipeline::PeerRouterState s = pipeline::readPeerRouterState(path, names_);
      size_t n = 0;
      for (const auto& h : s.provenance) n += h.size();
      spdlog::warn("restart: provenance journal of t = {} s ({} entries) in {}, taken at the first input", formatSeconds(s.t),
                   n, path);
      relay_.restoreAtFirstData(std::move(s.provenance), s.t);
    } catch (const std::exception& ex) {
      spdlog::error("provenance journal not used: {}", ex.what());
    }
  }

  void handled(const std::vector<pipeline::PeerRangeFeed::Routed>& routed) {
    for (const auto& r : routed) {
      buses_[r.receiver]->publishAs(vehicles_[r.receiver].name, channels::kPeerRange, r.range);
      ++sent_;
    }
    if (!o_.state_dir.empty() && relay_.dataTime() &&
        (!last_journal_ || (*relay_.dataTime() - *last_journal_).sec() >= o_.state_period_s))
      journal();
  }

  const PeerRouterOptions& o_;
  std::vector<std::string> names_;
  std::optional<Timestamp> last_journal_;
  std::vector<pipeline::Vehicle> vehicles_;
  std::vector<transport::LcmNode*> buses_;
  pipeline::PeerRangeRelay relay_;
  int64_t sent_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
  transport::ProcessMain process(
      "peer_router",
      "Routes a fleet's ranges between two vehicles' tags over LCM: subscribes every vehicle's RANGE, POSE and "
      "ANCHOR_INIT on its bus and publishes each inter-vehicle range, with where the other vehicle's POSE puts its "
      "tag, as PEER_RANGE to the one vehicle that fuses it (docs/fleet.md \"Inter-vehicle ranges over LCM\"; "
      "the choice is meshnav_run --fleet's). With --state-dir a respawn keeps whose information each vehicle holds. "
      "Counters at exit and every --progress seconds.");
  return process.run<PeerRouterOptions>(argc, argv, declareOptions, [&](PeerRouterOptions& o) {
    process.require(!o.fleet_path.empty(), "fleet");
    // Its journal is this process's alone: a second router on the folder is refused (exit 7).
    std::optional<DirLock> state_lock;
    if (!o.state_dir.empty()) state_lock.emplace(o.state_dir, "--state-dir");
    std::vector<pipeline::Vehicle> vehicles = pipeline::loadFleetVehicles(o.fleet_path);
    const SystemSetup fleet_setup = pipeline::mergeFleetSetups(vehicles, o.fleet_path);
    const std::vector<transport::LcmNode*> buses =
        process.fleetBuses(vehicles.size(), transport::parseFleetBus(o.bus), "");
    Diagnostics& diag = process.lcm().diagnostics();
    PeerRouterProcess router(o, vehicles, fleet_setup, buses, diag);
    spdlog::info("{}; {}", o.routing.toString(), o.relay.toString());
    router.connect();
    std::string where;
    for (size_t k = 0; k < vehicles.size(); ++k)
      where += (k ? ", " : "") + vehicles[k].name + " on " + buses[k]->url();
    spdlog::info("LCM {}", where);
    process.lcm().setHeartbeat(Duration::fromSec(o.progress_s), [&] {
      spdlog::info("{} PEER_RANGE sent, {} waiting; counters: {}", router.sent(), router.held(),
                   transport::formatCounters(diag.snapshot()));
    });
    const int rc = router.spin();
    router.journal();
    spdlog::info("stopped: {} PEER_RANGE sent, {} waiting; counters: {}", router.sent(), router.held(),
                 transport::formatCounters(diag.snapshot()));
    return rc;
  });
}
