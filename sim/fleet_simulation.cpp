/// @file fleet_simulation.cpp
/// @brief simulateFleet: one world, N vehicles, one anchor mesh.

#include "sim/fleet_simulation.h"

#include <algorithm>
#include <stdexcept>

#include "sim/scenario_simulator.h"

namespace meshnav::sim {

namespace {

bool anchorToAnchor(const RangeSample& r) {
  return r.type_initiator == UwbType::Anchor && r.type_responder == UwbType::Anchor;
}

}  // namespace

std::vector<SimulationResult> simulateFleet(const SimulationOptions& options, int n_vehicles) {
  if (n_vehicles < 1 || n_vehicles > 16) throw std::invalid_argument("a simulated fleet has 1 to 16 vehicles");
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
    ranges.insert(ranges.end(), mesh.begin(), mesh.end());
    std::stable_sort(ranges.begin(), ranges.end(),
                     [](const SimulatedRange& a, const SimulatedRange& b) { return a.sample.t < b.sample.t; });
    fleet[k].dataset.ranges.clear();
    for (const SimulatedRange& r : ranges) fleet[k].dataset.ranges.push_back(r.sample);
    fleet[k].ranges = std::move(ranges);
  }
  return fleet;
}

}  // namespace meshnav::sim
