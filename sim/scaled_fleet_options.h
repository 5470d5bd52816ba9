#pragma once
/// @file scaled_fleet_options.h
/// @brief What defines a scaled fleet (`meshnav_sim --vehicles N --anchors M --hall X,Y,Z`,
/// sim/scaled_fleet_simulation.h, docs/scenarios.md "A hundred anchors in TDMA cells").

#include <Eigen/Core>
#include <string>

#include "sim/cell_range_simulator.h"
#include "sim/cell_tdma_schedule.h"
#include "sim/simulation_options.h"

namespace meshnav::sim {

struct ScaledFleetOptions {
  /// Everything per vehicle but the scenario: seed (vehicle k flies seed + k), noise, IMU grade,
  /// duration (default 140 s), hall (`hall_size_m`, default 40 × 40 × 10 m).
  SimulationOptions base;
  int n_vehicles = 5;         ///< 1–16
  int n_anchors = 100;        ///< 4–400, on the grid of GridAnchorLayout
  int n_fly_by = -1;          ///< anchors not in setup.yaml; −1: 20 % of n_anchors
  double region_fraction = 0.6;  ///< each vehicle flies in a box of this fraction of the hall's X and Y [-]
  CellTdmaOptions tdma;
  CellOutage outage;          ///< the anchors switched off for one vehicle (default: none)
  /// Mission: the fly-by anchors are calibrated at these fractions of the duration [-].
  double calibrate_at_fraction = 0.55;
  double calibrate_again_at_fraction = 0.75;

  Eigen::Vector3d hallSize() const;
  /// n_fly_by, or 20 % of n_anchors.
  int flyByCount() const;
  /// Throws std::invalid_argument naming the bad value.
  void validate() const;
  std::string toString() const;
};

}  // namespace meshnav::sim
