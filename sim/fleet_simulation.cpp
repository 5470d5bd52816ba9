/// @file fleet_simulation.cpp
/// @brief simulateFleet: one world, N vehicles, one anchor mesh.

#include "sim/fleet_simulation.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/pose_interpolation.h"
#include "sim/random_stream.h"
#include "sim/scenario_simulator.h"

namespace meshnav::sim {

namespace {

bool anchorToAnchor(const RangeSample& r) {
  return r.type_initiator == UwbType::Anchor && r.type_responder == UwbType::Anchor;
}

/// Vehicle j's tags ranging to vehicle k's (simulateFleet's `inter_vehicle_hz`), appended to j's.
void addInterVehicleRanges(SimulationResult& vj, const SimulationResult& vk, size_t j, size_t k,
                           const SimulationOptions& o, double rate_hz) {
  const auto& gj = vj.dataset.ground_truth;
  const auto& gk = vk.dataset.ground_truth;
  if (gj.empty() || gk.empty()) return;
  std::vector<std::pair<SensorId, SensorId>> pairs;
  for (const auto& [tj, lj] : vj.dataset.setup.rel_tag_positions)
    for (const auto& [tk, lk] : vk.dataset.setup.rel_tag_positions) pairs.emplace_back(tj, tk);
  if (pairs.empty()) return;
  std::vector<double> gamma;
  for (const auto& [tj, tk] : pairs) {
    RandomStream hw(RandomStream::deriveSeed(o.hardware.hardware_seed,
                                             "pair:" + std::to_string(tj) + "-" + std::to_string(tk)));
    gamma.push_back(std::clamp(hw.gaussian(o.hardware.gamma_sigma_m), -o.hardware.gamma_max_m, o.hardware.gamma_max_m));
  }
  RandomStream noise(RandomStream::deriveSeed(o.seed, "inter-vehicle:" + std::to_string(j) + "-" + std::to_string(k)));
  const Timestamp t0 = std::max(gj.front().t, gk.front().t), t1 = std::min(gj.back().t, gk.back().t);
  const Duration step = Duration::fromSec(1.0 / rate_hz);
  size_t i = 0;
  for (Timestamp t = t0; t <= t1; t = t + step, ++i) {
    const auto pj = interpolatePose(gj, t), pk = interpolatePose(gk, t);
    if (!pj || !pk) continue;
    const size_t n = i % pairs.size();
    const auto& [tj, tk] = pairs[n];
    const Eigen::Vector3d p_tj = pj->p_IinG + pj->q_ItoG * vj.dataset.setup.rel_tag_positions.at(tj);
    const Eigen::Vector3d p_tk = pk->p_IinG + pk->q_ItoG * vk.dataset.setup.rel_tag_positions.at(tk);
    const double d = (p_tk - p_tj).norm();
    SimulatedRange r;
    r.sample.t = t;
    r.sample.id_initiator = tj;
    r.sample.id_responder = tk;
    r.sample.type_initiator = r.sample.type_responder = UwbType::Tag;
    r.sample.range_m = r.sample.range_corr_m = d + gamma[n] + noise.gaussian(o.uwb.sigma_range_m);
    r.true_distance_m = d;
    vj.ranges.push_back(r);
  }
}

}  // namespace

std::vector<SimulationResult> simulateFleet(const SimulationOptions& options, int n_vehicles, double inter_vehicle_hz) {
  if (n_vehicles < 1 || n_vehicles > 16) throw std::invalid_argument("a simulated fleet has 1 to 16 vehicles");
  if (!(inter_vehicle_hz >= 0.0) || !std::isfinite(inter_vehicle_hz))
    throw std::invalid_argument("inter-vehicle ranging rate must be >= 0 Hz");
  std::vector<SimulationResult> fleet;
  for (int k = 0; k < n_vehicles; ++k) {
    SimulationOptions o = options;
    o.seed = options.seed + static_cast<uint64_t>(k);
    o.layout_seed = options.layout_seed.value_or(options.seed);
    o.tag_id_offset = options.tag_id_offset + 1000 * k;
    o.validate();
    fleet.push_back(ScenarioSimulator(o).run());
  }
  // Vehicle 0's mesh for everyone: drop each other vehicle's own anchor–anchor ranges, add vehicle 0's.
  std::vector<SimulatedRange> mesh;
  for (const SimulatedRange& r : fleet.front().ranges)
    if (anchorToAnchor(r.sample)) mesh.push_back(r);
  for (size_t k = 1; k < fleet.size(); ++k) {
    std::vector<SimulatedRange> ranges;
    for (const SimulatedRange& r : fleet[k].ranges)
      if (!anchorToAnchor(r.sample)) ranges.push_back(r);
    // Within the vehicle's own recording: a mesh range after its last IMU sample would be an input
    // its estimate can never reach (meshnav_run: exit 5).
    const Timestamp end = fleet[k].dataset.imu.empty() ? Timestamp{0} : fleet[k].dataset.imu.back().t;
    for (const SimulatedRange& r : mesh)
      if (r.sample.t <= end) ranges.push_back(r);
    fleet[k].ranges = std::move(ranges);
  }
  if (inter_vehicle_hz > 0.0)
    for (size_t j = 0; j < fleet.size(); ++j)
      for (size_t k = j + 1; k < fleet.size(); ++k) addInterVehicleRanges(fleet[j], fleet[k], j, k, options, inter_vehicle_hz);
  for (size_t k = (inter_vehicle_hz > 0.0 ? 0 : 1); k < fleet.size(); ++k) {
    auto& ranges = fleet[k].ranges;
    std::stable_sort(ranges.begin(), ranges.end(),
                     [](const SimulatedRange& a, const SimulatedRange& b) { return a.sample.t < b.sample.t; });
    fleet[k].dataset.ranges.clear();
    for (const SimulatedRange& r : ranges) fleet[k].dataset.ranges.push_back(r.sample);
  }
  return fleet;
}

}  // namespace meshnav::sim
