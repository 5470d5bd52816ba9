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

/// Throws std::invalid_argument for n_vehicles outside [1, 16], a negative or non-finite
/// `inter_vehicle_hz`, or invalid options.
///
/// `inter_vehicle_hz` > 0: every pair of vehicles (j < k) also ranges tag to tag, at that rate,
/// one tag pair per exchange in turn (TDMA-like), each range in vehicle j's ranges (its tag is the
/// initiator): z = d + γ + ν from the two true trajectories (ground truth, tags' lever arms), ν ~
/// N(0, σ_d²), γ per tag pair drawn from the hardware seed like every pair's (N(0, σ_γ²), clipped),
/// no outliers. 0: none (the default).
std::vector<SimulationResult> simulateFleet(const SimulationOptions& options, int n_vehicles, double inter_vehicle_hz = 0.0);

}  // namespace meshnav::sim
