#pragma once
/// @file fleet_simulation.h
/// @brief A simulated fleet (`meshnav_sim --fleet N`, docs/fleet.md): N vehicles in one hall among
/// the same anchors. Vehicle k flies the scenario of the options with seed `seed + k` (its own
/// trajectory, IMU, baro and range noise), the anchor layout of `seed` (one world), and tag ids
/// + 1000·k. The anchors' mesh is one: every vehicle's dataset carries vehicle 0's anchor–anchor
/// ranges, the same samples (the fleet pipeline hands each range to the calibrator once). The
/// UWB hardware biases come from the hardware seed, so every vehicle sees the same anchor–anchor γ.

#include <vector>

#include "sim/simulation_options.h"
#include "sim/simulation_result.h"

namespace meshnav::sim {

/// Throws std::invalid_argument for n_vehicles outside [1, 16] or invalid options.
std::vector<SimulationResult> simulateFleet(const SimulationOptions& options, int n_vehicles);

}  // namespace meshnav::sim
