#pragma once
/// @file scenario_simulator.h
/// @brief Simulates one sequence (the paper's scenario by default, or a generated one; docs/scenarios.md): analytic motion,
/// IMU, barometer (flights only), meshed-TDMA UWB ranges over every tag and anchor, flight state
/// (motions with a landed phase only), ground truth, setup.yaml and truth.yaml.

#include <optional>

#include "sim/paper_scenario.h"
#include "sim/simulation_options.h"
#include "sim/simulation_result.h"

namespace meshnav::sim {

class ScenarioSimulator {
 public:
  /// `scenario`: the hardware geometry; nullopt: `buildScenario(options)` (the paper's by default).
  explicit ScenarioSimulator(SimulationOptions options, std::optional<PaperScenario> scenario = std::nullopt);
  /// Deterministic for given options: the same seed gives the same result.
  SimulationResult run() const;
  const SimulationOptions& options() const { return options_; }
  const PaperScenario& scenario() const { return scenario_; }

 private:
  SimulationOptions options_;
  PaperScenario scenario_;
};

}  // namespace meshnav::sim
