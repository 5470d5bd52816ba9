#pragma once
/// @file inertial_streams.h
/// @brief The inputs the imu_bridge replays from a dataset folder (docs/formats.md): imu.csv → IMU,
/// baro.csv → BARO, flight_state.csv → FLIGHT_STATE, height.csv → HEIGHT, merged into one
/// deterministic time line.

#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "common/types.h"
#include "transport/replay/replay_event.h"

namespace meshnav::imu {

struct InertialStreams {
  std::vector<ImuSample> imu;
  std::vector<BaroSample> baro;
  std::vector<FlightStateSample> flight_states;
  std::vector<HeightSample> heights;

  /// Stream indices of ReplayEvent::stream. At equal times the timeline keeps this order, which is
  /// the estimator's canonical order (flight state, IMU, baro), so a replay causes no rewinds.
  static constexpr int kFlightStateStream = 0;
  static constexpr int kImuStream = 1;
  static constexpr int kBaroStream = 2;
  static constexpr int kHeightStream = 3;  ///< last, as HEIGHT is last in the estimator's order

  /// The streams merged by time (equal times: in the order of the stream indices).
  std::vector<replay::ReplayEvent> timeline() const;
  size_t size() const { return imu.size() + baro.size() + flight_states.size() + heights.size(); }
};

/// Reads imu.csv, baro.csv, flight_state.csv and height.csv of `dataset_dir`; each file is optional, but at
/// least one must exist (else std::runtime_error naming the folder). Bad rows are reported and
/// counted in `diag` (file:line) and dropped.
InertialStreams loadInertialStreams(const std::string& dataset_dir, Diagnostics& diag);

}  // namespace meshnav::imu
