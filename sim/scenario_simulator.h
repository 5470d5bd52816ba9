#pragma once
/// @file scenario_simulator.h
/// @brief Simulates one sequence of the paper's scenario (DESIGN §7): analytic flight, IMU,
/// barometer, meshed-TDMA UWB ranges, flight state, ground truth, setup.yaml and truth.yaml.

#include "sim/paper_scenario.h"
#include "sim/simulation_options.h"
#include "sim/simulation_result.h"

namespace meshnav::sim {

class ScenarioSimulator {
 public:
  explicit ScenarioSimulator(SimulationOptions options, PaperScenario scenario = PaperScenario::paper());
  /// Deterministic for given options: the same seed gives the same result.
  SimulationResult run() const;
  const SimulationOptions& options() const { return options_; }

 private:
  SimulationOptions options_;
  PaperScenario scenario_;
};

}  // namespace meshnav::sim
