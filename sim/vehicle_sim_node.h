#pragma once
/// @file vehicle_sim_node.h
/// @brief The simulated vehicle as a node (the `vehicle_sim` process, docs/closed_loop.md "Over
/// LCM"); free of LCM. A SimulatedVehicle stepped at the dynamics' rate; its samples, after the
/// drill's SensorFaults, go to the sinks (IMU, BARO, RANGE, FLIGHT_STATE, and the truth at every
/// IMU instant, for evaluation only); the controller's commands act from their arrival on.
///
/// Lock-step: after a step that published IMU samples the node awaits the command stamped with
/// the newest of them (`awaiting()`): the front end handles messages until it comes, or declares it
/// late (`commandLate()`: counted, the last command kept) after a wall-time timeout. A command
/// older than the newest applied one is ignored (counted). The flight ends (`done()`) on a crash,
/// after `max_duration_s`, or `after_touchdown_s` after the controller reported `landed`.

#include <functional>
#include <optional>
#include <string>

#include "common/types.h"
#include "sim/sensor_faults.h"
#include "sim/simulated_vehicle.h"

namespace meshnav::sim {

struct VehicleSimNodeOptions {
  SimulatedVehicleOptions vehicle;  ///< seed in vehicle.sensors.seed
  SensorFaultOptions faults;        ///< drill faults (none by default)
  double max_duration_s = 400.0;    ///< stop here whatever happened [s]
  double after_touchdown_s = 2.0;   ///< keep running after the controller reported landed [s]
};

struct VehicleSimSinks {
  std::function<void(const ImuSample&)> imu;
  std::function<void(const BaroSample&)> baro;
  std::function<void(const RangeSample&)> range;
  std::function<void(const FlightStateSample&)> flight_state;
  /// The true pose at every IMU instant (also during an IMU gap), with the vehicle off the floor.
  std::function<void(const PoseSample&, bool airborne)> truth;
};

struct VehicleSimCounters {
  int64_t steps = 0, imu = 0, baro = 0, ranges = 0, flight_states = 0;
  int64_t commands = 0;          ///< commands applied
  int64_t commands_late = 0;     ///< lock-step: awaited commands that did not come in time
  int64_t commands_stale = 0;    ///< commands older than the newest applied one (ignored)
};

class VehicleSimNode {
 public:
  VehicleSimNode(const VehicleSimNodeOptions& options, VehicleSimSinks sinks);

  const SimulatedVehicle& vehicle() const { return vehicle_; }
  const SensorFaults& faults() const { return faults_; }
  double time() const { return vehicle_.time(); }

  /// The samples due at time 0 (once, before the first step).
  void start();
  /// One integration step and its samples.
  void step();

  /// The IMU instant whose command the vehicle waits for in lock-step (none: go on).
  std::optional<Timestamp> awaiting() const { return awaiting_; }
  /// A command of the controller: `t` the instant it answers, `controller_landed` its mode.
  void onCommand(Timestamp t, const QuadrotorCommand& command, bool controller_landed);
  /// The awaited command did not come in time: the last one stays.
  void commandLate();

  bool done() const;
  /// Why the flight ended ("" while it runs): "crash: ...", "landed", "max duration".
  std::string endReason() const;
  const VehicleSimCounters& counters() const { return counters_; }

 private:
  void emit(VehicleOutputs out);

  VehicleSimNodeOptions options_;
  VehicleSimSinks sinks_;
  SimulatedVehicle vehicle_;
  SensorFaults faults_;
  std::optional<Timestamp> awaiting_, last_command_;
  std::optional<double> touchdown_s_;
  VehicleSimCounters counters_;
};

}  // namespace meshnav::sim
