/// peer_router: a fleet's ranges between two vehicles' tags over LCM (docs/fleet.md "Inter-vehicle
/// ranges over LCM"), pipeline::PeerRangeRelay on the vehicles' buses.
///   every vehicle's P/RANGE, P/POSE, P/ANCHOR_INIT -> the receiving vehicle's P/PEER_RANGE.
/// Vehicle k's channels are on its bus (--bus, as the fleet launch's); which vehicle fuses a range
/// and with what is pipeline::PeerRangeFeed's, as in meshnav_run --fleet.
#include <memory>
#include <string>
#include <vector>

#include "pipeline/fleet.h"
#include "pipeline/peer_range_relay.h"
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
};

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
  cli.option("progress", o.progress_s, "wall seconds between two progress lines (counters)")->type_name("S")->check(cli::positive());
}

/// The relay wired to each vehicle's bus.
class PeerRouterProcess {
 public:
  PeerRouterProcess(const PeerRouterOptions& o, const std::vector<pipeline::Vehicle>& vehicles, const SystemSetup& fleet_setup,
                    std::vector<transport::LcmNode*> buses, Diagnostics& diag)
      : vehicles_(vehicles), buses_(std::move(buses)), relay_(vehicles, fleet_setup, o.routing, o.relay, diag) {}

  void connect() {
    for (size_t v = 0; v < vehicles_.size(); ++v) {
      transport::LcmNode& bus = *buses_[v];
      const std::string& p = vehicles_[v].name;
      bus.subscribeAs(p, channels::kRange, [this, v](const RangeSample& r) { send(relay_.onRange(v, r)); });
      bus.subscribeAs(p, channels::kPose, [this, v](const PoseEstimate& pe) { send(relay_.onPose(v, pe)); });
      // Every vehicle gets each ANCHOR_INIT (the fleet's calibrator); the relay notes an anchor once.
      bus.subscribeAs(p, channels::kAnchorInit, [this](const AnchorInit& a) { relay_.onAnchorInit(a.id); });
    }
  }

  int spin() { return transport::LcmNode::spinAll(buses_); }

  int64_t sent() const { return sent_; }
  size_t held() const { return relay_.held(); }

 private:
  void send(const std::vector<pipeline::PeerRangeFeed::Routed>& routed) {
    for (const auto& r : routed) {
      buses_[r.receiver]->publishAs(vehicles_[r.receiver].name, channels::kPeerRange, r.range);
      ++sent_;
    }
  }

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
      "the choice is meshnav_run --fleet's). Counters at exit and every --progress seconds.");
  return process.run<PeerRouterOptions>(argc, argv, declareOptions, [&](PeerRouterOptions& o) {
    process.require(!o.fleet_path.empty(), "fleet");
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
    spdlog::info("stopped: {} PEER_RANGE sent, {} waiting; counters: {}", router.sent(), router.held(),
                 transport::formatCounters(diag.snapshot()));
    return rc;
  });
}
