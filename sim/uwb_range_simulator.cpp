#include "sim/uwb_range_simulator.h"

#include <sstream>
#include <stdexcept>

#include "sim/random_stream.h"

namespace meshnav::sim {

std::string UwbRangeOptions::toString() const {
  std::ostringstream s;
  s << "uwb ranges: slot " << slot_s << " s, sigma " << sigma_range_m << " m, outliers " << outlier_fraction
    << " (+U(" << outlier_min_m << ", " << outlier_max_m << ") m), drops " << drop_fraction;
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

std::vector<SimulatedRange> UwbRangeSimulator::simulate(const Trajectory& trajectory,
                                                        const TdmaSchedule& schedule, double t_end_s) {
  RandomStream rng(RandomStream::deriveSeed(seed_, "uwb_ranges"));
  n_slots_ = n_dropped_ = n_outliers_ = 0;
  std::vector<SimulatedRange> out;
  for (const TdmaSlot& slot : schedule.slotsUntil(t_end_s)) {
    ++n_slots_;
    // Fixed number of draws per slot (see file comment).
    const double u_drop = rng.uniform();
    const double u_outlier = rng.uniform();
    const double noise = rng.gaussian();
    const double excess = rng.uniform(options_.outlier_min_m, options_.outlier_max_m);
    if (u_drop < options_.drop_fraction) {
      ++n_dropped_;
      continue;
    }
    const TrajectoryState st = trajectory.evaluate(slot.t_s);
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
    r.sample.t = Timestamp::fromSec(slot.t_s);
    r.sample.id_initiator = slot.initiator;
    r.sample.id_responder = slot.responder;
    r.sample.type_initiator = scenario_.typeOf(slot.initiator);
    r.sample.type_responder = scenario_.typeOf(slot.responder);
    r.sample.range_m = z;
    r.sample.range_corr_m = z;
    r.sample.R_m2 = options_.sigma_range_m * options_.sigma_range_m;
    r.sample.los = true;
    out.push_back(r);
  }
  return out;
}

}  // namespace meshnav::sim
