#pragma once
/// @file sensor_fault_cli.h
/// @brief The drills' sensor faults (sim/sensor_faults.h) on a command line, the same options for
/// `meshnav fly` (one process) and `vehicle_sim` (over LCM): --anchor-off ID, --anchor-off-at T,
/// --range-loss F, --range-loss-from T and, where the controller keeps its own clock (one process),
/// --imu-gap A,B.

#include <cstdint>
#include <vector>

#include "common/cli.h"
#include "sim/sensor_faults.h"

namespace meshnav::sim {

struct SensorFaultArgs {
  std::vector<double> imu_gap;  ///< A, B [s]
  int64_t anchor_off = 0;       ///< 0: none
  double anchor_off_at_s = 0.0, range_loss = 0.0, range_loss_from_s = 0.0;

  /// The options these arguments say (validated: throws std::invalid_argument naming the value).
  SensorFaultOptions options() const;
};

/// Declares the options on `cli`; `with_imu_gap` adds --imu-gap.
void declareSensorFaultOptions(Cli& cli, SensorFaultArgs& args, bool with_imu_gap);

}  // namespace meshnav::sim
