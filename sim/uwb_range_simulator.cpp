#include "sim/uwb_range_simulator.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "sim/random_stream.h"

namespace meshnav::sim {

std::string UwbRangeOptions::toString() const {
  std::ostringstream s;
  s << "uwb ranges: slot " << slot_s << " s, sigma " << sigma_range_m << " m";
  if (correlation_time_s > 0.0) s << " (correlation time " << correlation_time_s << " s)";
  s << ", outliers " << outlier_fraction;
  if (nlos_excess == "exponential")
    s << " (+" << outlier_min_m << " m + Exp(mean " << outlier_mean_m << " m))";
  else
    s << " (+U(" << outlier_min_m << ", " << outlier_max_m << ") m)";
  s << ", drops " << drop_fraction;
  if (time_offset_s != 0.0) s << ", stamps " << time_offset_s * 1e3 << " ms late against the IMU";
  return s.str();
}

UwbRangeSimulator::UwbRangeSimulator(const PaperScenario& scenario, const UwbHardwareBiases& biases,
                                     const UwbRangeOptions& options, uint64_t seed)
    : scenario_(scenario), biases_(biases), options_(options), seed_(seed) {}

Eigen::Vector3d UwbRangeSimulator::devicePosition(SensorId id, const TrajectoryState& st) const {
  if (const auto it = scenario_.tags_p_TinI.find(id); it != scenario_.tags_p_TinI.end())
    return st.p_IinG + st.R_ItoG * it->second;
  if (const auto it = scenario_.anchors_p_AinG.find(id); it != scenario_.anchors_p_AinG.end()) return it->second;
  throw std::out_of_range("UwbRangeSimulator: unknown device " + std::to_string(id));
}

void UwbRangeSimulator::reset() {
  rng_.reset();
  next_slot_ = 0;
  n_slots_ = n_dropped_ = n_outliers_ = 0;
  pair_error_.clear();
}

std::vector<SimulatedRange> UwbRangeSimulator::simulate(const Trajectory& trajectory,
                                                        const TdmaSchedule& schedule, double t_end_s) {
  reset();
  return simulateUntil([&](double t) { return trajectory.evaluate(t); }, schedule, t_end_s);
}

std::vector<SimulatedRange> UwbRangeSimulator::simulateUntil(const StateAt& state_at, const TdmaSchedule& schedule,
                                                             double t_end_s) {
  if (!rng_) rng_.emplace(RandomStream::deriveSeed(seed_, "uwb_ranges"));
  std::vector<SimulatedRange> out;
  // The slots of slotsUntil(t_end_s), taken one by one from where the previous call stopped.
  for (const int64_t n = schedule.slotCountUntil(t_end_s); next_slot_ < n; ++next_slot_)
    if (auto r = drawSlot(schedule.slot(next_slot_), state_at, *rng_)) out.push_back(*r);
  return out;
}

std::optional<SimulatedRange> UwbRangeSimulator::drawSlot(const TdmaSlot& slot, const StateAt& state_at,
                                                          RandomStream& rng) {
  ++n_slots_;
  // Fixed number of draws per slot (see file comment).
  const double u_drop = rng.uniform();
  const double u_outlier = rng.uniform();
  const double n = rng.gaussian();
  const double u_excess = rng.uniform();
  const double excess = options_.nlos_excess == "exponential"
                            ? options_.outlier_min_m - options_.outlier_mean_m * std::log1p(-u_excess)
                            : options_.outlier_min_m + (options_.outlier_max_m - options_.outlier_min_m) * u_excess;
  // The pair's unit error: independent, or a first-order process over its slots (dropped ones too).
  double noise = n;
  if (options_.correlation_time_s > 0.0) {
    const auto key = pairKey(slot.initiator, slot.responder);
    auto it = pair_error_.find(key);
    if (it != pair_error_.end()) {
      const double rho = std::exp(-(slot.t_s - it->second.first) / options_.correlation_time_s);
      noise = rho * it->second.second + std::sqrt(1.0 - rho * rho) * n;
    }
    pair_error_[key] = {slot.t_s, noise};
  }
  if (u_drop < options_.drop_fraction) {
    ++n_dropped_;
    return std::nullopt;
  }
  const double stamp_s = slot.t_s + options_.time_offset_s;  // the UWB clock's stamp of the instant slot.t_s
  if (stamp_s < 0.0) return std::nullopt;
  const TrajectoryState st = state_at(slot.t_s);
  const double d = (devicePosition(slot.initiator, st) - devicePosition(slot.responder, st)).norm();
  const PairBias& bias = biases_.truth(slot.initiator, slot.responder);
  SimulatedRange r;
  r.true_distance_m = d;
  r.outlier = u_outlier < options_.outlier_fraction;
  double z = bias.beta * d + bias.gamma_m + options_.sigma_range_m * noise;
  if (r.outlier) {
    z += excess;
    ++n_outliers_;
  }
  r.sample.t = Timestamp::fromSec(stamp_s);
  r.sample.id_initiator = slot.initiator;
  r.sample.id_responder = slot.responder;
  r.sample.type_initiator = scenario_.typeOf(slot.initiator);
  r.sample.type_responder = scenario_.typeOf(slot.responder);
  r.sample.range_m = z;
  r.sample.range_corr_m = z;
  r.sample.R_m2 = options_.sigma_range_m * options_.sigma_range_m;
  r.sample.los = true;
  return r;
}

}  // namespace meshnav::sim
