#pragma once
/// @file baro_simulator.h
/// @brief Barometer: static pressure at the sensor's height with white noise.
///
/// p_PinG = p_IinG + R_ItoG p_IP;  pressure = p_atm(h = z of p_PinG; p_ref) + n,  n ~ N(0, σ²),
/// with the standard atmosphere of `common/atmosphere.h`; p_ref is the pressure at the hall floor
/// level z = 0 (seeded around 97000 Pa, i.e. a site ~400 m above sea level).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/types.h"
#include "sim/random_stream.h"
#include "sim/trajectory.h"

namespace meshnav::sim {

struct BaroOptions {
  double rate_hz = 50.0;                                ///< sample rate [Hz]
  double pressure_sigma_pa = 3.0;                       ///< white noise σ [Pa] (≈ 0.25 m)
  Eigen::Vector3d p_IP = Eigen::Vector3d(0, 0, 0.05);   ///< sensor in the IMU frame [m]
  double reference_pressure_pa = 97000.0;               ///< pressure at z = 0 [Pa]
  std::string toString() const;
};

class BaroSimulator {
 public:
  BaroSimulator(const BaroOptions& options, uint64_t seed);
  /// Noise-free pressure [Pa] for a state.
  double idealPressure(const TrajectoryState& state) const;
  /// Readings at t_k = k/rate for t_k ∈ [0, t_end_s].
  std::vector<BaroSample> simulate(const Trajectory& trajectory, double t_end_s) const;
  /// Step-wise sampling (a closed-loop vehicle): the next reading for the exact state at its time,
  /// drawn from the same stream in the same order as `simulate` (the caller keeps the 1/rate grid).
  BaroSample sample(const TrajectoryState& state);
  const BaroOptions& options() const { return options_; }

 private:
  /// The reading for `state` with one draw of `rng`.
  BaroSample draw(const TrajectoryState& state, RandomStream& rng) const;

  BaroOptions options_;
  uint64_t seed_;
  std::optional<RandomStream> rng_;  ///< step-wise stream (sample)
};

}  // namespace meshnav::sim
