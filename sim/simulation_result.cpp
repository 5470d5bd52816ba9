#include "sim/simulation_result.h"

#include <cstdio>

namespace meshnav::sim {

std::string SimulationResult::summary() const {
  const auto& ds = dataset;
  const double n_written = static_cast<double>(ds.ranges.size());
  char phases[96] = "no landed phase";
  if (has_landed_phase) std::snprintf(phases, sizeof(phases), "take-off %.1f s, touch-down %.1f s", takeoff_time_s, touchdown_time_s);
  char buf[1024];
  std::snprintf(buf, sizeof(buf),
                "Simulated %.1f s of %s (%s, top %.2f m): %zu IMU samples, %zu baro "
                "samples, %zu ranges from %lld TDMA slots (%lld dropped, %lld outliers injected = %.1f %% of the "
                "written ranges), %zu flight states, %zu ground-truth poses; %zu known and %zu true anchors, %zu "
                "a-priori pair biases.",
                stats.duration_s, trajectory_kind.c_str(), phases, stats.max_height_m, ds.imu.size(),
                ds.baro.size(), ds.ranges.size(), static_cast<long long>(stats.n_range_slots),
                static_cast<long long>(stats.n_dropped), static_cast<long long>(stats.n_outliers),
                n_written > 0 ? 100.0 * static_cast<double>(stats.n_outliers) / n_written : 0.0,
                ds.flight_states.size(), ds.ground_truth.size(), ds.setup.abs_anchor_positions.size(),
                ds.truth ? ds.truth->anchor_positions.size() : size_t{0}, ds.setup.pair_biases.size());
  return buf;
}

}  // namespace meshnav::sim
