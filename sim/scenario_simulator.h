#pragma once
/// @file scenario_simulator.h
/// @brief Simulates one sequence (the paper's scenario by default, or a generated one; docs/scenarios.md): analytic motion,
/// IMU, barometer (flights only), meshed-TDMA UWB ranges over every tag and anchor, flight state
/// (motions with a landed phase only), ground truth, setup.yaml and truth.yaml.

#include <optional>

#include "common/setup.h"
#include "sim/baro_simulator.h"
#include "sim/paper_scenario.h"
#include "sim/simulation_options.h"
#include "sim/simulation_result.h"

namespace meshnav::sim {

class Trajectory;
class UwbHardwareBiases;

/// setup.yaml of a sequence: what a user knows (ids, tags' lever arms, the known anchors and the
/// a-priori pair biases among tags and known anchors, baro lever arm, the pad prior drawn around
/// the trajectory's pose at 0, the noise figures). Also the closed-loop vehicle's
/// (sim/simulated_vehicle.h), with a trajectory that rests on its pad.
SystemSetup makeSetup(const SimulationOptions& o, const PaperScenario& scenario, const Trajectory& trajectory,
                      const UwbHardwareBiases& biases, const BaroOptions& baro_options);

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
