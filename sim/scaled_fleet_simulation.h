#pragma once
/// @file scaled_fleet_simulation.h
/// @brief A fleet among a hundred anchors in TDMA cells (`meshnav_sim --vehicles N --anchors M
/// --hall X,Y,Z`, docs/scenarios.md "A hundred anchors in TDMA cells").
///
/// One world: the anchors of `GridAnchorLayout` (seed `base.seed`), `n_fly_by` of them only in
/// truth.yaml; one set of UWB modules (the hardware seed: every pair's γ, β the same in every
/// vehicle's files). Vehicle k: seed + k, tags 100 + 1000 k and 105 + 1000 k (the paper's lever
/// arms), its own flight fitted to its **region**, a box of `region_fraction` of the hall's X and
/// Y, full height, centred at the hall centre + 0.2·(X cos θ_k, Y sin θ_k), θ_k = θ₀ + 2πk/N (one
/// vehicle: at the centre), and of kind spiral, figure8, lawnmower, helix in turn from a seeded
/// first one (θ₀ and that first kind from `deriveSeed(seed, "scaled_fleet")`). IMU, baro, ground
/// truth, flight state, setup.yaml and truth.yaml as `ScenarioSimulator` writes them for that
/// vehicle; the ranges from `CellRangeSimulator`: each vehicle's file holds what its tags initiated
/// (to anchors and to other vehicles' tags) and the whole anchor mesh within its recording.
/// setup.yaml's a-priori pair biases (and truth.yaml's) are those of pairs that can range: a tag
/// with any anchor, two anchors of neighbouring cells.

#include <string>
#include <vector>

#include "sim/scaled_fleet_options.h"
#include "sim/simulation_result.h"

namespace meshnav::sim {

struct ScaledFleet {
  std::vector<SimulationResult> vehicles;
  std::vector<CellRangeStats> range_stats;  ///< per vehicle
  std::vector<Hall> regions;                ///< per vehicle
  std::string layout_csv;    ///< id,x_m,y_m,z_m,cell,cell_x,cell_y,mount,known (one line per anchor)
  std::string mission_yaml;  ///< calibrate every fly-by anchor at the two fractions of the flight
  std::string description;   ///< layout, cells, schedule and range rates, one line each
};

/// Throws std::invalid_argument for invalid options.
ScaledFleet simulateScaledFleet(const ScaledFleetOptions& options);

/// Vehicle k's flight region (see the file comment).
Hall scaledFleetRegion(const Hall& hall, int k, int n_vehicles, double region_fraction, double theta0_rad);

}  // namespace meshnav::sim
