#pragma once
/// @file simulation_result.h
/// @brief Output of one simulated sequence: the dataset (what gets written) plus what only the
/// simulator knows.

#include <cstdint>
#include <string>
#include <vector>

#include "common/dataset.h"
#include "sim/uwb_range_simulator.h"

namespace meshnav::sim {

struct SimulationStats {
  double duration_s = 0.0;
  int64_t n_range_slots = 0;   ///< TDMA slots in the sequence
  int64_t n_dropped = 0;       ///< dropped messages
  int64_t n_outliers = 0;      ///< outliers injected among the written ranges
  double max_height_m = 0.0;   ///< highest IMU z [m]
};

struct SimulationResult {
  Dataset dataset;                     ///< files of docs/formats.md (setup.yaml, truth.yaml included)
  std::vector<SimulatedRange> ranges;  ///< same order as dataset.ranges, with outlier flags
  std::string trajectory_kind;         ///< "spiral", "walk", ...
  std::string trajectory_description; ///< the motion's parameters (Trajectory::toString)
  bool has_landed_phase = true;        ///< false: no flight_state.csv (walk, hover)
  double takeoff_time_s = 0.0;         ///< end of the initial landed phase [s]
  double touchdown_time_s = 0.0;       ///< start of the final landed phase [s]
  SimulationStats stats;
  /// One paragraph for the user: duration, counts, outliers.
  std::string summary() const;
};

}  // namespace meshnav::sim
