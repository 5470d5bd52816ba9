#pragma once
/// @file simulated_vehicle.h
/// @brief The closed-loop vehicle (issue 37, docs/closed_loop.md): QuadrotorDynamics flown by
/// commands, sampled step by step by the project's sensor models — IMU (ImuSimulator::sample), baro
/// (BaroSimulator::sample), meshed-TDMA UWB ranges with NLOS outliers and drops
/// (UwbRangeSimulator::simulateUntil), the ground-contact switch as FLIGHT_STATE — and, for
/// evaluation only, the ground truth.
///
/// Time: the dynamics' fixed step Δt (1 kHz by default); every `step()` advances one Δt and returns
/// the sensor samples that fell due in it: IMU at t_k = k/rate_imu (the state at the step nearest
/// t_k, stamped t_k; the IMU rate must divide the integration rate), baro at k/rate_baro, ranges of
/// every TDMA slot up to now (the vehicle's state linearly interpolated between the two steps
/// around the slot time), flight state at its rate, truth at every IMU sample.
/// The seeds are those of the sequence simulator (SimulationOptions::seed, the same stream names),
/// so IMU biases, range noise and hardware biases are drawn as for a dataset of that seed.

#include <cstdint>
#include <optional>
#include <vector>

#include "common/setup.h"
#include "common/types.h"
#include "sim/baro_simulator.h"
#include "sim/imu_simulator.h"
#include "sim/paper_scenario.h"
#include "sim/quadrotor_dynamics.h"
#include "sim/simulation_options.h"
#include "sim/tdma_schedule.h"
#include "sim/uwb_hardware_biases.h"
#include "sim/uwb_range_simulator.h"

namespace meshnav::sim {

struct SimulatedVehicleOptions {
  SimulationOptions sensors;     ///< seed, IMU, baro, UWB, hardware biases, pad prior σ, rates
  QuadrotorOptions dynamics;
  Eigen::Vector3d pad_p_m = Eigen::Vector3d(0.0, -2.0, 0.0);  ///< take-off pad (x, y; z is the pad height) [m]
  double pad_yaw_rad = 0.0;      ///< heading on the pad [rad]
};

/// What one step produced (each list in time order).
struct VehicleOutputs {
  std::vector<ImuSample> imu;
  std::vector<BaroSample> baro;
  std::vector<SimulatedRange> ranges;
  std::vector<FlightStateSample> flight_states;
  std::vector<PoseSample> truth;  ///< evaluation only
};

class SimulatedVehicle {
 public:
  /// `scenario`: nullopt = `buildScenario(options.sensors)` (the paper's by default). Throws
  /// std::invalid_argument when the IMU rate does not divide the integration rate.
  explicit SimulatedVehicle(const SimulatedVehicleOptions& options, std::optional<PaperScenario> scenario = std::nullopt);
  SimulatedVehicle(const SimulatedVehicle&) = delete;  // the range simulator refers to its biases
  SimulatedVehicle& operator=(const SimulatedVehicle&) = delete;

  /// What the system may know (setup.yaml): as for a dataset of the seed, with the pad prior drawn
  /// around the pad.
  const SystemSetup& setup() const { return setup_; }
  /// True anchors, pair biases and drawn values (evaluation only).
  const Truth& truth() const { return truth_; }
  const PaperScenario& scenario() const { return scenario_; }
  const QuadrotorDynamics& dynamics() const { return dyn_; }
  const Eigen::Vector3d& pad() const { return pad_; }

  /// The command that acts from now on.
  void setCommand(const QuadrotorCommand& command) { dyn_.setCommand(command); }
  /// Samples due at time 0 (call once before the first `step`).
  VehicleOutputs start();
  /// One integration step and the samples due in it.
  VehicleOutputs step();
  double time() const { return dyn_.time(); }

 private:
  /// The exact state at `t_s` between the previous and the current step (linear in p, v; slerp).
  TrajectoryState stateAt(double t_s) const;
  void sampleDue(VehicleOutputs& out);

  SimulatedVehicleOptions options_;
  PaperScenario scenario_;
  Eigen::Vector3d pad_;
  QuadrotorDynamics dyn_;
  TrajectoryState prev_, cur_;
  ImuSimulator imu_;
  std::optional<BaroSimulator> baro_;
  std::optional<TdmaSchedule> schedule_;
  std::optional<UwbHardwareBiases> biases_;
  std::optional<UwbRangeSimulator> uwb_;
  SystemSetup setup_;
  Truth truth_;
  int64_t steps_per_imu_ = 5;
  int64_t n_imu_ = 0, n_baro_ = 0, n_flight_ = 0;
};

}  // namespace meshnav::sim
