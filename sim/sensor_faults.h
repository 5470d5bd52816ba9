#pragma once
/// @file sensor_faults.h
/// @brief Sensor faults of the closed-loop fault drills (issue 37 item 4, docs/closed_loop.md): what
/// the vehicle's sensors lose on their way to the estimator. Applied to a step's VehicleOutputs
/// (sim/simulated_vehicle.h) before they are handed on; the truth is never touched.
///  - IMU gaps: no IMU sample with t in [from, to) (the estimator sees a gap; in one process the
///    controller still runs at those instants: the flight controller has its own IMU);
///  - an anchor switched off at a time: no range with it as initiator or responder from then on;
///  - RANGE loss: each range dropped with probability `range_loss_fraction` from `range_loss_from_s`
///    (a stream of its own, RandomStream "range_loss" of the seed: the other sensors' noise is
///    the same as without the fault).
/// Without a fault configured nothing is drawn and the outputs pass unchanged.

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/types.h"
#include "sim/random_stream.h"
#include "sim/simulated_vehicle.h"

namespace meshnav::sim {

struct SensorFaultOptions {
  std::vector<std::pair<double, double>> imu_gaps_s;  ///< [from, to) windows without IMU [s]
  std::optional<SensorId> anchor_off;                 ///< anchor switched off ...
  double anchor_off_from_s = 0.0;                     ///< ... from this time on [s]
  double range_loss_fraction = 0.0;                   ///< probability that a range is lost [0, 1)
  double range_loss_from_s = 0.0;                     ///< ... from this time on [s]
  bool any() const { return !imu_gaps_s.empty() || anchor_off || range_loss_fraction > 0.0; }
  /// One line, for logs ("none" without a fault).
  std::string toString() const;
  /// Throws std::invalid_argument naming the value (an empty or reversed window, a fraction
  /// outside [0, 1)).
  void validate() const;
};

class SensorFaults {
 public:
  SensorFaults(SensorFaultOptions options, uint64_t seed);

  /// Removes the lost samples from `out` (the truth stays).
  void apply(VehicleOutputs& out);
  /// True when IMU samples at `t` are lost.
  bool imuLost(Timestamp t) const;

  const SensorFaultOptions& options() const { return options_; }
  int64_t imuDropped() const { return imu_dropped_; }
  int64_t rangesAnchorOff() const { return ranges_anchor_off_; }
  int64_t rangesLost() const { return ranges_lost_; }

 private:
  SensorFaultOptions options_;
  RandomStream rng_;
  int64_t imu_dropped_ = 0, ranges_anchor_off_ = 0, ranges_lost_ = 0;
};

}  // namespace meshnav::sim
