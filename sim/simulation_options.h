#pragma once
/// @file simulation_options.h
/// @brief Everything that defines one simulated sequence: the paper's scenario by default, or a
/// generated one (trajectory kind, hall, anchor layout, tags, known/unknown anchors, duration).

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "sim/baro_simulator.h"
#include "sim/anchor_layout.h"
#include "sim/hall.h"
#include "sim/imu_simulator.h"
#include "sim/spiral_trajectory.h"
#include "sim/trajectory_kind.h"
#include "sim/uwb_hardware_biases.h"
#include "sim/uwb_range_simulator.h"

namespace meshnav::sim {

struct SimulationOptions {
  uint64_t seed = 1;                         ///< sequence seed (1–12: the twelve sequences)
  double duration_scale = 1.0;               ///< multiplies every time constant of the flight (1: ~140 s)
  bool with_initial_pose = true;             ///< write `initial_pose` (take-off pad prior) to setup.yaml
  double initial_pose_sigma_p_m = 0.05;      ///< error σ of the pad prior's position [m] (per axis)
  double initial_pose_sigma_yaw_deg = 2.0;   ///< error σ of the pad prior's yaw [deg]
  double reference_pressure_mean_pa = 97000.0;    ///< pressure at z = 0, mean over seeds [Pa]
  double reference_pressure_spread_pa = 500.0;    ///< ± uniform spread of the seeded value [Pa]
  double ground_truth_rate_hz = 60.0;        ///< groundtruth.csv rate [Hz]
  double flight_state_rate_hz = 10.0;        ///< flight_state.csv rate [Hz]
  ImuNoiseOptions imu;
  BaroOptions baro;                          ///< `reference_pressure_pa` is replaced by the seeded value
  UwbRangeOptions uwb;
  UwbHardwareOptions hardware;
  /// Spiral flight shape; nullopt: `TrajectoryOptions::randomized(seed, duration_scale)`.
  std::optional<TrajectoryOptions> trajectory;
  // Scenario generator (defaults: the paper's scenario, docs/scenarios.md).
  TrajectoryKind trajectory_kind = TrajectoryKind::Spiral;  ///< --trajectory
  std::optional<Eigen::Vector3d> hall_size_m;   ///< --hall X,Y,Z [m]; nullopt: the paper's hall
  AnchorLayoutKind anchor_layout = AnchorLayoutKind::Paper;  ///< --anchor-layout
  int n_tags = 2;                               ///< --tags: 1 (100), 2 (+105), 3 (+99)
  int n_known_anchors = 4;                      ///< --known: anchors written to setup.yaml (3–5)
  int n_unknown_anchors = 5;                    ///< --unknown: further anchors, truth.yaml only
  std::optional<double> duration_s;             ///< --duration [s]; nullopt: 140 s × duration_scale
  /// A fleet's vehicle k (--fleet, fleet_simulation.h): its tags' ids are the single vehicle's + this
  /// (1000·k), so that every tag of the fleet has its own id.
  int tag_id_offset = 0;
  /// Seed of the anchor layout (a fleet's one world: every vehicle among the same anchors);
  /// nullopt: `seed`.
  std::optional<uint64_t> layout_seed;
  /// The box the trajectory is fitted to, inside the hall (a scaled fleet's vehicle flies its own
  /// part of a large hall, sim/scaled_fleet_simulation.h); nullopt: the hall.
  std::optional<Hall> flight_region;
  /// False: ScenarioSimulator writes no ranges (a caller simulates them: the cell TDMA of a scaled
  /// fleet); its truth.yaml range counts are then 0.
  bool mesh_ranges = true;

  /// The hall box: `Hall::ofSize(*hall_size_m)` or the paper's.
  Hall hall() const { return hall_size_m ? Hall::ofSize(*hall_size_m) : Hall::paper(); }
  /// True for the paper's geometry (spiral, paper hall, paper anchors, two tags, 101–104 known,
  /// 106–110 unknown): then the outputs are those of the paper-scenario simulator.
  bool isPaperScenario() const;

  /// Throws std::invalid_argument naming the offending option.
  void validate() const;
  std::string toString() const;
};

}  // namespace meshnav::sim
