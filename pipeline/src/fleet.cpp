/// @file fleet.cpp
/// @brief Fleet file, the merged anchor map, per-vehicle ANCHOR_INITs and the merged input order.

#include "pipeline/fleet.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <stdexcept>

#include "common/setup.h"
#include "common/yaml_options.h"

namespace meshnav::pipeline {

namespace {

bool samePairBias(const PairBias& x, const PairBias& y) {
  constexpr double kTol = 1e-9;
  return std::abs(x.gamma_m - y.gamma_m) <= kTol && std::abs(x.beta - y.beta) <= kTol &&
         std::abs(x.sigma_m - y.sigma_m) <= kTol && std::abs(x.sigma_gamma_m - y.sigma_gamma_m) <= kTol &&
         std::abs(x.sigma_beta - y.sigma_beta) <= kTol;
}

}  // namespace

std::vector<Vehicle> loadFleetVehicles(const std::string& path) {
  std::vector<Vehicle> vehicles;
  for (const FleetEntry& e : loadFleetFile(path))
    vehicles.push_back({e.name, loadSetup((std::filesystem::path(e.dataset) / "setup.yaml").string())});
  return vehicles;
}

SystemSetup mergeFleetSetups(std::vector<Vehicle>& vehicles, const std::string& where) {
  if (vehicles.empty()) throw std::invalid_argument(where + ": a fleet needs at least one vehicle");
  auto fail = [&](const std::string& what) { throw std::invalid_argument(where + ": " + what); };
  SystemSetup fleet = vehicles.front().setup;
  fleet.rel_tag_positions.clear();
  fleet.abs_anchor_positions.clear();
  fleet.abs_anchor_sigmas_m.clear();
  fleet.pair_biases.clear();
  std::map<SensorId, std::string> owner;  // tag → vehicle
  std::map<SensorId, std::string> anchor_from, sigma_from;
  std::map<std::pair<SensorId, SensorId>, std::pair<PairBias, std::string>> pairs;
  for (const Vehicle& v : vehicles) {
    for (const auto& [tag, lever] : v.setup.rel_tag_positions) {
      if (const auto o = owner.find(tag); o != owner.end())
        fail("tag " + std::to_string(tag) + " of " + v.name + " is also a tag of " + o->second +
             " (every tag id must be unique in the fleet)");
      owner[tag] = v.name;
      fleet.rel_tag_positions[tag] = lever;
    }
    for (const auto& [id, p] : v.setup.abs_anchor_positions) {
      if (const auto k = fleet.abs_anchor_positions.find(id); k != fleet.abs_anchor_positions.end()) {
        if ((k->second - p).norm() > 1e-3)
          fail("anchor " + std::to_string(id) + " is at a different position in " + v.name + " than in " +
               anchor_from[id] + " (" + std::to_string((k->second - p).norm()) + " m apart; the fleet shares one map)");
      } else {
        fleet.abs_anchor_positions[id] = p;
        anchor_from[id] = v.name;
      }
    }
    for (const auto& [id, s] : v.setup.abs_anchor_sigmas_m) {
      if (const auto k = fleet.abs_anchor_sigmas_m.find(id); k != fleet.abs_anchor_sigmas_m.end()) {
        if (std::abs(k->second - s) > 1e-9)
          fail("anchor " + std::to_string(id) + " has a different abs_anchor_sigmas in " + v.name + " than in " +
               sigma_from[id]);
      } else {
        fleet.abs_anchor_sigmas_m[id] = s;
        sigma_from[id] = v.name;
      }
    }
    for (const PairBias& b : v.setup.pair_biases) {
      const auto key = pairKey(b.a, b.b);
      if (const auto k = pairs.find(key); k != pairs.end()) {
        if (!samePairBias(k->second.first, b))
          fail("the pair bias " + std::to_string(key.first) + "-" + std::to_string(key.second) + " of " + v.name +
               " differs from " + k->second.second + "'s");
      } else {
        pairs.emplace(key, std::make_pair(b, v.name));
        fleet.pair_biases.push_back(b);
      }
    }
  }
  // A tag id must not be a device of another kind anywhere in the fleet.
  for (const auto& [tag, name] : owner) {
    if (fleet.abs_anchor_positions.count(tag))
      fail("tag " + std::to_string(tag) + " of " + name + " is a known anchor of " + anchor_from[tag]);
    for (const Vehicle& v : vehicles)
      if (tag == v.setup.imu_id || tag == v.setup.baro_id)
        fail("tag " + std::to_string(tag) + " of " + name + " has the IMU's or the baro's id of " + v.name);
  }
  // Every vehicle knows the shared map; of the pair biases it gets those not involving another's tag.
  for (Vehicle& v : vehicles) {
    v.setup.abs_anchor_positions = fleet.abs_anchor_positions;
    v.setup.abs_anchor_sigmas_m = fleet.abs_anchor_sigmas_m;
    std::vector<PairBias> mine;
    for (const PairBias& b : fleet.pair_biases) {
      const bool foreign = (owner.count(b.a) && owner[b.a] != v.name) || (owner.count(b.b) && owner[b.b] != v.name);
      if (!foreign) mine.push_back(b);
    }
    v.setup.pair_biases = std::move(mine);
  }
  return fleet;
}

AnchorInit restrictToVehicle(const AnchorInit& a, const SystemSetup& vehicle, const SystemSetup& fleet) {
  std::vector<Eigen::Index> keep;
  for (size_t i = 0; i < a.biases.size(); ++i) {
    const PairBias& b = a.biases[i];
    const SensorId peer = b.a == a.id ? b.b : b.a;
    if (!fleet.isTag(peer) || vehicle.isTag(peer)) keep.push_back(static_cast<Eigen::Index>(i));
  }
  if (keep.size() == a.biases.size()) return a;
  AnchorInit r = a;
  r.biases.clear();
  for (const Eigen::Index i : keep) r.biases.push_back(a.biases[static_cast<size_t>(i)]);
  if (a.hasJointCovariance() && a.jointCovarianceError().empty()) {
    const auto n = static_cast<Eigen::Index>(keep.size());
    r.cov_gamma_p_m2.resize(n, 3);
    r.cov_gamma_m2.resize(n, n);
    for (Eigen::Index i = 0; i < n; ++i) {
      r.cov_gamma_p_m2.row(i) = a.cov_gamma_p_m2.row(keep[static_cast<size_t>(i)]);
      for (Eigen::Index j = 0; j < n; ++j)
        r.cov_gamma_m2(i, j) = a.cov_gamma_m2(keep[static_cast<size_t>(i)], keep[static_cast<size_t>(j)]);
    }
  }
  return r;
}

std::vector<FleetInput> mergeFleetInputs(const std::vector<std::vector<estimator::EstimatorInput>>& per_vehicle) {
  std::vector<FleetInput> out;
  size_t n = 0;
  for (const auto& v : per_vehicle) n += v.size();
  out.reserve(n);
  for (size_t v = 0; v < per_vehicle.size(); ++v)
    for (const auto& in : per_vehicle[v]) out.push_back({v, in});
  // Stable on time alone: equal times keep the vehicle order, and each vehicle its own order.
  std::stable_sort(out.begin(), out.end(), [](const FleetInput& x, const FleetInput& y) {
    return estimator::inputTime(x.input) < estimator::inputTime(y.input);
  });
  return out;
}

}  // namespace meshnav::pipeline
