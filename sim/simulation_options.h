#pragma once
/// @file simulation_options.h
/// @brief Everything that defines one simulated sequence of the paper's scenario.

#include <cstdint>
#include <optional>
#include <string>

#include "sim/baro_simulator.h"
#include "sim/imu_simulator.h"
#include "sim/spiral_trajectory.h"
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
  /// Flight shape; nullopt: `TrajectoryOptions::randomized(seed, duration_scale)`.
  std::optional<TrajectoryOptions> trajectory;

  /// Throws std::invalid_argument naming the offending option.
  void validate() const;
  std::string toString() const;
};

}  // namespace meshnav::sim
