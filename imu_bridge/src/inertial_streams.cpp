#include "imu_bridge/inertial_streams.h"

#include <spdlog/spdlog.h>

#include <filesystem>
#include <stdexcept>

#include "common/dataset.h"

namespace meshnav::imu {

std::vector<replay::ReplayEvent> InertialStreams::timeline() const {
  return replay::mergeTimeline(
      {replay::timesOf(flight_states), replay::timesOf(imu), replay::timesOf(baro), replay::timesOf(heights)});
}

InertialStreams loadInertialStreams(const std::string& dataset_dir, Diagnostics& diag) {
  namespace fs = std::filesystem;
  const fs::path dir(dataset_dir);
  if (!fs::is_directory(dir)) throw std::runtime_error(dataset_dir + ": not a dataset folder");
  InertialStreams s;
  bool any = false;
  // Reads `name` into `samples` when the dataset has it.
  const auto read = [&](const char* name, auto& samples, auto reader) {
    if (!fs::exists(dir / name)) return;
    samples = reader((dir / name).string(), diag);
    any = true;
  };
  read("imu.csv", s.imu, readImuCsv);
  read("baro.csv", s.baro, readBaroCsv);
  read("flight_state.csv", s.flight_states, readFlightStateCsv);
  read("height.csv", s.heights, readHeightCsv);
  if (!any)
    throw std::runtime_error(dataset_dir + ": none of imu.csv, baro.csv, flight_state.csv, height.csv found");
  spdlog::info("{}: {} IMU, {} baro, {} flight-state, {} height samples", dataset_dir, s.imu.size(), s.baro.size(),
               s.flight_states.size(), s.heights.size());
  return s;
}

}  // namespace meshnav::imu
