#include "sim/vehicle_sim_node.h"

namespace meshnav::sim {

VehicleSimNode::VehicleSimNode(const VehicleSimNodeOptions& options, VehicleSimSinks sinks)
    : options_(options),
      sinks_(std::move(sinks)),
      vehicle_(options.vehicle),
      faults_(options.faults, options.vehicle.sensors.seed) {}

void VehicleSimNode::start() {
  vehicle_.setCommand({0.0, Eigen::Vector3d::Zero()});
  emit(vehicle_.start());
}

void VehicleSimNode::step() {
  ++counters_.steps;
  emit(vehicle_.step());
}

void VehicleSimNode::emit(VehicleOutputs out) {
  const bool airborne = !vehicle_.dynamics().landed();
  if (sinks_.truth)
    for (const auto& t : out.truth) sinks_.truth(t, airborne);
  faults_.apply(out);
  // The canonical order within a step (estimator_input.h): flight state, IMU, baro, ranges.
  for (const auto& s : out.flight_states) {
    ++counters_.flight_states;
    if (sinks_.flight_state) sinks_.flight_state(s);
  }
  for (const auto& s : out.imu) {
    ++counters_.imu;
    if (sinks_.imu) sinks_.imu(s);
    awaiting_ = s.t;
  }
  for (const auto& s : out.baro) {
    ++counters_.baro;
    if (sinks_.baro) sinks_.baro(s);
  }
  for (const auto& r : out.ranges) {
    ++counters_.ranges;
    if (sinks_.range) sinks_.range(r.sample);
  }
}

void VehicleSimNode::onCommand(Timestamp t, const QuadrotorCommand& command, bool controller_landed) {
  if (last_command_ && t < *last_command_) {
    ++counters_.commands_stale;
    return;
  }
  last_command_ = t;
  ++counters_.commands;
  vehicle_.setCommand(command);
  if (awaiting_ && t >= *awaiting_) awaiting_.reset();
  if (controller_landed && !touchdown_s_) touchdown_s_ = vehicle_.time();
}

void VehicleSimNode::commandLate() {
  ++counters_.commands_late;
  awaiting_.reset();
}

bool VehicleSimNode::done() const { return !endReason().empty(); }

std::string VehicleSimNode::endReason() const {
  if (vehicle_.dynamics().crashed()) return "crash: " + vehicle_.dynamics().crashReason();
  if (touchdown_s_ && vehicle_.time() - *touchdown_s_ >= options_.after_touchdown_s) return "landed";
  if (vehicle_.time() >= options_.max_duration_s) return "max duration";
  return "";
}

}  // namespace meshnav::sim
