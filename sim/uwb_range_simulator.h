#pragma once
/// @file uwb_range_simulator.h
/// @brief SDS-TWR ranges of the meshed TDMA: tag–anchor, anchor–anchor and tag–tag.
///
/// At slot time t between devices a (initiator) and b:
///   p_TinG = p_IinG(t) + R_ItoG(t) p_TinI for a tag, p_AinG for an anchor,  d = ‖p_a − p_b‖,
///   z = β_ab d + γ_ab + σ_d e,  e ~ N(0, 1),
/// and with probability ε an NLOS-like outlier adds a positive error, U(o_min, o_max) (`uniform`,
/// the paper's) or o_min + Exp(mean o_mean) (`exponential`: most of its mass within a few tenths of
/// a metre, as on real hardware, where a χ² gate does not see it); with probability δ the message
/// is dropped. With a correlation time τ > 0 the unit error of a pair (either direction) is a
/// first-order process, e_k = ρ e_{k−1} + √(1 − ρ²) n_k, ρ = exp(−Δt/τ), Δt since the pair's
/// previous slot (real multipath changes with the geometry, slowly: STAR-loc, docs/uwb_bias_model.md);
/// τ = 0: independent. Every slot consumes the same random draws whatever the options, so e.g.
/// disabling noise leaves the outlier pattern unchanged, and the defaults draw the paper's ranges.
/// With a time offset δ the UWB system stamps late (or early, δ < 0) against the IMU's clock: the
/// distance at t is written with stamp t + δ (issue 34 measured STAR-loc's IMU stamps leading its
/// ranges by about 30 ms); a range whose stamp would be before 0 is not written.
/// The written `R` is σ_d², `range_corr` equals the raw range, `LOS` is always 1 (as in real data,
/// where the flag carries no information; outliers are marked only in `SimulatedRange`).

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/types.h"
#include "sim/paper_scenario.h"
#include "sim/random_stream.h"
#include "sim/trajectory.h"
#include "sim/tdma_schedule.h"
#include "sim/uwb_hardware_biases.h"

namespace meshnav::sim {

struct UwbRangeOptions {
  double slot_s = 0.01;            ///< TDMA slot Δt [s]
  double sigma_range_m = 0.1;      ///< σ_d [m]
  double outlier_fraction = 0.05;  ///< ε [-]
  double outlier_min_m = 0.5;      ///< smallest NLOS excess [m]
  double outlier_max_m = 3.0;      ///< largest NLOS excess [m] (uniform)
  std::string nlos_excess = "uniform";  ///< uniform | exponential
  double outlier_mean_m = 0.3;     ///< mean excess beyond outlier_min_m (exponential) [m]
  double correlation_time_s = 0.0;  ///< τ of a pair's range error, 0 = independent [s]
  double drop_fraction = 0.02;     ///< δ [-]
  double time_offset_s = 0.0;      ///< the stamps' delay against the IMU clock: d(t) is stamped t + this [s]
  std::string toString() const;
};

/// A range with what only the simulator knows.
struct SimulatedRange {
  RangeSample sample;
  double true_distance_m = 0.0;  ///< d
  bool outlier = false;
};

class UwbRangeSimulator {
 public:
  UwbRangeSimulator(const PaperScenario& scenario, const UwbHardwareBiases& biases, const UwbRangeOptions& options,
                    uint64_t seed);

  /// Position of a device in G for the UAV state (tags move with I, anchors are fixed) [m].
  Eigen::Vector3d devicePosition(SensorId id, const TrajectoryState& state) const;
  /// Ranges of every non-dropped slot of `schedule` up to `t_end_s`.
  std::vector<SimulatedRange> simulate(const Trajectory& trajectory, const TdmaSchedule& schedule,
                                       double t_end_s);

  /// The vehicle's exact state at a slot time (a closed loop's vehicle interpolates its steps).
  using StateAt = std::function<TrajectoryState(double t_s)>;
  /// Step-wise sampling (a closed-loop vehicle): the ranges of the slots of `schedule` after the
  /// last one taken so far up to `t_end_s`, with the same draws in the same order as `simulate`
  /// (which is `reset` + one call of this over the whole trajectory). Counters accumulate.
  std::vector<SimulatedRange> simulateUntil(const StateAt& state_at, const TdmaSchedule& schedule, double t_end_s);
  /// Forgets the step-wise progress: the next `simulateUntil` starts at slot 0 with a fresh stream.
  void reset();

  int64_t slotCount() const { return n_slots_; }
  int64_t droppedCount() const { return n_dropped_; }
  int64_t outlierCount() const { return n_outliers_; }

 private:
  /// One slot: its fixed draws from `rng`, then the range (nullopt: dropped, or stamped before 0).
  std::optional<SimulatedRange> drawSlot(const TdmaSlot& slot, const StateAt& state_at, RandomStream& rng);

  std::map<std::pair<SensorId, SensorId>, std::pair<double, double>> pair_error_;  ///< pair → (t [s], e)
  std::optional<RandomStream> rng_;  ///< step-wise stream
  int64_t next_slot_ = 0;            ///< step-wise: first slot not taken yet
  PaperScenario scenario_;
  const UwbHardwareBiases& biases_;
  UwbRangeOptions options_;
  uint64_t seed_;
  int64_t n_slots_ = 0, n_dropped_ = 0, n_outliers_ = 0;
};

}  // namespace meshnav::sim
