/// meshnav_lcm_probe: receives IMU, RANGE, POSE (and counts every other channel) and writes what
/// `./meshnav bench lcm` reports (scripts/bench_lcm.sh): IMU → POSE and RANGE → POSE latency
/// (median, p99, max) from its own receive times, lost messages (IMU without POSE, POSE without
/// IMU, RANGE without POSE) and messages per second per channel (transport/latency_recorder.h says
/// what each figure is). With --channel-prefixes P1,P2,... (a fleet over LCM, `bench lcm --fleet`)
/// it does so per vehicle, on each vehicle's channels (channels::prefixed); with --fleet FILE the
/// prefixes are the fleet's vehicle names and RANGE → POSE is over each vehicle's tag–anchor ranges
/// (its setup.yaml's tags), the others (anchor mesh, tag to tag) measured apart. A fleet's vehicles
/// each have their own LCM bus by default (--bus per-vehicle, transport/fleet_bus.h, as
/// meshnav_fleet_launch writes them): the probe then opens one LCM instance per bus and polls them
/// all from its one thread (the receive times are LCM's, taken in each instance's receive thread).
/// It runs until SIGINT/SIGTERM or --duration, then writes --out (YAML) and prints it.

#include <cerrno>
#include <chrono>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#include "common/cli.h"
#include "common/fleet_file.h"
#include "common/setup.h"
#include "transport/channels.h"
#include "transport/convert.h"
#include "transport/fleet_bus.h"
#include "transport/latency_recorder.h"
#include "transport/lcm_node.h"
#include "transport/stop_signal.h"
#include "transport/wire_versions.h"

namespace {

using namespace meshnav;
using namespace meshnav::transport;

/// The data time [µs] of a message of `channel`'s type, or nothing when it does not decode.
template <class T>
std::optional<int64_t> utimeOf(channels::Channel<T>, const lcm::ReceiveBuffer& rbuf) {
  WireType<T> msg;
  try {
    if (decodeAnyVersion(rbuf.data, rbuf.data_size, msg) < 0) return std::nullopt;
  } catch (const std::exception&) {
    return std::nullopt;
  }
  return msg.utime;
}

/// The figures of one recorder, as YAML lines indented by `indent`.
std::string figures(const LatencyRecorder& rec, const std::string& indent) {
  std::ostringstream y;
  auto stats = [&](const char* name, const LatencyStats& s) {
    y << indent << name << ": {n: " << s.n << ", median_us: " << s.median_us << ", p99_us: " << s.p99_us
      << ", max_us: " << s.max_us << "}\n";
  };
  stats("imu_to_pose", rec.imuToPose());
  stats("range_to_pose", rec.rangeToPose());
  // Where the tail is: RANGE answered later than 2 ms (issue 38's bound), per 10 s of data time.
  y << indent << "range_to_pose_over_2ms_per_10s: {";
  bool first = true;
  for (const auto& [t, n] : rec.rangeToPoseOverByWindow(2000.0, 10.0)) {
    y << (first ? "" : ", ") << t << ": " << n;
    first = false;
  }
  y << "}  # window start [s of data time]: RANGE answered later than 2 ms\n";
  if (rec.otherRangeToPose().n > 0) stats("other_range_to_pose", rec.otherRangeToPose());
  y << indent << "fused_ranges: " << rec.fusedRanges() << "  # RANGE the estimator updates with (all without --fleet)\n";
  y << indent << "ranges_unanswered: " << rec.rangesUnanswered() << "  # received before the last POSE, answered by none\n";
  y << indent << "ranges_after_last_pose: " << rec.rangesAfterLastPose() << "  # the end of the data: no POSE could answer them\n";
  y << indent << "ranges_before_first_pose: " << rec.rangesBeforeFirstPose()
    << "  # stamped before the estimator initialized: not in RANGE -> POSE\n";
  y << indent << "imus_unanswered: " << rec.imusUnanswered() << "  # IMU between the first and the last POSE without its POSE\n";
  y << indent << "poses_without_imu: " << rec.posesWithoutImu() << "  # POSE whose IMU sample the probe did not receive\n";
  y << indent << "channels:\n";
  const auto rates = rec.ratesHz();
  for (const auto& [ch, n] : rec.counts())
    y << indent << "  " << ch << ": {messages: " << n << ", per_s: " << rates.at(ch) << "}\n";
  return y.str();
}

}  // namespace

int main(int argc, char** argv) {
  Cli cli("meshnav_lcm_probe",
          "Measures IMU -> POSE and RANGE -> POSE latency (median, p99, max, from this process's receive times), lost "
          "messages and messages per second per channel over LCM, for one vehicle or per vehicle of a fleet "
          "(--channel-prefixes), until SIGINT/SIGTERM or --duration; writes --out (YAML).");
  std::string out, url, prefix_list, fleet_file, bus_name = "per-vehicle", samples_path;
  double duration_s = 0.0;
  cli.optional("out", out, "where to write the figures (YAML)")->type_name("FILE")->required();
  cli.option("duration", duration_s, "stop after S seconds of wall time (0: at SIGINT/SIGTERM) [s]")
      ->type_name("S")
      ->check(CLI::NonNegativeNumber);
  cli.optional("lcm-url", url,
               "LCM provider; with a fleet and --bus per-vehicle the base URL of the buses (default: LCM_DEFAULT_URL)")
      ->type_name("URL");
  cli.optional("channel-prefixes", prefix_list,
               "a fleet: measure each vehicle on its own channels P/IMU, P/RANGE, P/POSE (docs/channels.md); the "
               "figures go under vehicles: P: in --out (default: one vehicle, unprefixed channels)")
      ->type_name("P1,P2,...")
      ->check(CLI::Validator(
          [](std::string& list) {
            std::stringstream ss(list);
            std::string p;
            std::set<std::string> seen;
            while (std::getline(ss, p, ',')) {
              if (const std::string why = channels::prefixProblem(p); !why.empty()) return why;
              if (!seen.insert(p).second) return "'" + p + "' is given twice";
            }
            return seen.empty() ? std::string("no prefix given") : std::string();
          },
          "", "vehicle prefixes"));
  cli.optional("fleet", fleet_file,
               "a fleet file (docs/fleet.md): its vehicle names are the prefixes, and each vehicle's RANGE -> POSE is "
               "over the ranges of its tags (its setup.yaml) to anchors; the others (anchor mesh, tag to tag) go to "
               "other_range_to_pose")
      ->type_name("FILE")
      ->excludes("--channel-prefixes");
  cli.option("bus", bus_name,
             "a fleet's buses, as meshnav_fleet_launch --bus: per-vehicle (vehicle k, its index in --fleet or "
             "--channel-prefixes from 0, on the --lcm-url's port + 1 + k) or shared (every vehicle on --lcm-url)")
      ->type_name("POLICY")
      ->check(CLI::IsMember({"per-vehicle", "shared"}));
  cli.optional("samples", samples_path,
               "also write every answered tag-anchor RANGE as a CSV row vehicle,t_s,range_to_pose_us,pose_t_s,range_last "
               "(t: its data time, pose_t: the answering POSE's [s]; range_last 1: the RANGE came after that POSE's IMU "
               "sample): where in the flight the tail is")
      ->type_name("FILE");
  int code = 0;
  if (!cli.parse(argc, argv, code)) return code;
  StopSignal::install();
  std::vector<std::string> prefixes;
  std::map<std::string, std::set<SensorId>> tags;  // prefix -> its tags (--fleet)
  std::set<SensorId> every_tag;
  try {
    if (!fleet_file.empty()) {
      for (const FleetEntry& v : loadFleetFile(fleet_file)) {
        prefixes.push_back(v.name);
        for (const auto& [id, p] : loadSetup(v.dataset + "/setup.yaml").rel_tag_positions) {
          tags[v.name].insert(id);
          every_tag.insert(id);
        }
      }
    }
  } catch (const std::exception& ex) {
    std::cerr << "meshnav_lcm_probe: " << ex.what() << "\n";
    return 1;
  }
  {
    std::stringstream ss(prefix_list);
    for (std::string p; std::getline(ss, p, ',');) prefixes.push_back(p);
  }
  // A range the estimator of `prefix` fuses: one of its tags to a device that is no tag (with --fleet).
  auto fused = [&](const std::string& prefix, const RangeSample& r) {
    const auto it = tags.find(prefix);
    if (it == tags.end()) return true;
    const bool a = it->second.count(r.id_initiator) > 0, b = it->second.count(r.id_responder) > 0;
    return (a && !every_tag.count(r.id_responder)) || (b && !every_tag.count(r.id_initiator));
  };
  const bool fleet = !prefixes.empty();
  if (!fleet) prefixes.push_back("");
  std::map<std::string, LatencyRecorder> per_vehicle;  // prefix -> its recorder
  LatencyRecorder all;                                 // every channel counted (a fleet's totals)
  // One LCM instance per bus: bus_of[k] is vehicle k's, buses[i] the vehicles on bus i.
  std::vector<std::unique_ptr<LcmNode>> nodes;
  std::vector<std::vector<std::string>> buses;
  std::vector<LatencyRecorder> per_bus;  // the channels heard on each bus
  try {
    const FleetBus bus = fleet ? parseFleetBus(bus_name) : FleetBus::kShared;
    const std::string base_url = resolveLcmUrl(url);
    std::map<std::string, size_t> bus_of_url;
    std::vector<size_t> bus_of;
    for (size_t k = 0; k < prefixes.size(); ++k) {
      const std::string u = vehicleLcmUrl(bus, base_url, k);
      auto [it, added] = bus_of_url.emplace(u, nodes.size());
      if (added) {
        nodes.push_back(std::make_unique<LcmNode>("lcm_probe", u));
        buses.emplace_back();
      }
      bus_of.push_back(it->second);
      buses[it->second].push_back(prefixes[k]);
    }
    per_bus.resize(nodes.size());
    for (size_t k = 0; k < prefixes.size(); ++k) {
      const std::string& p = prefixes[k];
      LcmNode& node = *nodes[bus_of[k]];
      LatencyRecorder& rec = per_vehicle[p];
      const std::string imu = channels::prefixed(channels::kImu, p), range = channels::prefixed(channels::kRange, p),
                        pose = channels::prefixed(channels::kPose, p);
      node.subscribeRaw(imu, [&rec](const lcm::ReceiveBuffer& rb, const std::string&) {
        if (auto u = utimeOf(channels::kImu, rb)) rec.onImu(*u, rb.recv_utime);
      });
      node.subscribeRaw(range, [&rec, &fused, p](const lcm::ReceiveBuffer& rb, const std::string&) {
        WireType<RangeSample> msg;
        try {
          if (decodeAnyVersion(rb.data, rb.data_size, msg) < 0) return;
          rec.onRange(msg.utime, rb.recv_utime, fused(p, fromWire<RangeSample>(msg)));
        } catch (const std::exception&) {
        }
      });
      node.subscribeRaw(pose, [&rec](const lcm::ReceiveBuffer& rb, const std::string&) {
        if (auto u = utimeOf(channels::kPose, rb)) rec.onPose(*u, rb.recv_utime);
      });
    }
    // Every channel of every bus once more: the totals, each bus's, and each vehicle's other
    // channels (by their prefix).
    for (size_t i = 0; i < nodes.size(); ++i) {
      nodes[i]->subscribeRaw(".*", [&, i](const lcm::ReceiveBuffer& rb, const std::string& ch) {
        all.onOther(ch, rb.recv_utime);
        per_bus[i].onOther(ch, rb.recv_utime);
        const std::string_view base = channels::unprefixedName(ch);
        if (base == channels::kImu.name || base == channels::kRange.name || base == channels::kPose.name) return;
        const std::string prefix = ch.size() > base.size() ? ch.substr(0, ch.size() - base.size() - 1) : "";
        if (auto it = per_vehicle.find(prefix); it != per_vehicle.end()) it->second.onOther(std::string(base), rb.recv_utime);
      });
    }
    std::cout << "lcm_probe: listening on";
    for (size_t i = 0; i < nodes.size(); ++i) std::cout << (i ? ", " : " ") << nodes[i]->url();
    std::cout << (fleet ? " for " + std::to_string(prefixes.size()) + " vehicles" : std::string()) << std::endl;
    const auto start = std::chrono::steady_clock::now();
    auto until = [&] {
      return duration_s > 0.0 &&
             std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= duration_s;
    };
    std::vector<LcmNode*> all;
    for (auto& n : nodes) all.push_back(n.get());
    if (LcmNode::spinAll(all, until) != 0) return 1;
  } catch (const std::exception& ex) {
    std::cerr << "meshnav_lcm_probe: " << ex.what() << "\n";
    return 1;
  }
  std::ostringstream y;
  if (!fleet) {
    y << figures(per_vehicle.at(""), "");
  } else {
    y << "vehicles:\n";
    for (const std::string& p : prefixes) y << "  " << p << ":\n" << figures(per_vehicle.at(p), "    ");
    const auto rates = all.ratesHz();
    y << "channels:  # every channel of every bus\n";
    for (const auto& [ch, n] : all.counts()) y << "  " << ch << ": {messages: " << n << ", per_s: " << rates.at(ch) << "}\n";
    y << "buses:  # each LCM bus listened on (--bus " << bus_name << "): its vehicles and the messages heard on it\n";
    for (size_t i = 0; i < nodes.size(); ++i) {
      y << "  - url: \"" << nodes[i]->url() << "\"\n    vehicles: [";
      for (size_t k = 0; k < buses[i].size(); ++k) y << (k ? ", " : "") << buses[i][k];
      y << "]\n    channels: {";
      bool first = true;
      for (const auto& [ch, n] : per_bus[i].counts()) {
        y << (first ? "" : ", ") << ch << ": " << n;
        first = false;
      }
      y << "}\n";
    }
  }
  if (!samples_path.empty()) {
    std::ofstream s(samples_path);
    s << "vehicle,t_s,range_to_pose_us,pose_t_s,range_last\n";
    for (const auto& [p, rec] : per_vehicle)
      for (const auto& a : rec.rangeToPoseSamples())
        s << p << "," << Timestamp{a.utime}.sec() << "," << a.latency_us << "," << Timestamp{a.pose_utime}.sec() << ","
          << a.range_last << "\n";
    if (!s) {
      std::cerr << "meshnav_lcm_probe: cannot write " << samples_path << "\n";
      return 1;
    }
  }
  std::ofstream f(out);
  f << y.str();
  if (!f) {
    std::cerr << "meshnav_lcm_probe: cannot write " << out << "\n";
    return 1;
  }
  std::cout << y.str() << std::flush;
  return 0;
}
