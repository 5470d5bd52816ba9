#include "sim/baro_simulator.h"

#include <cmath>
#include <sstream>

#include "common/atmosphere.h"
#include "sim/random_stream.h"

namespace meshnav::sim {

std::string BaroOptions::toString() const {
  std::ostringstream s;
  s << "baro: " << rate_hz << " Hz, sigma " << pressure_sigma_pa << " Pa, p_IP [" << p_IP.transpose()
    << "] m, reference pressure " << reference_pressure_pa << " Pa at z = 0";
  return s.str();
}

BaroSimulator::BaroSimulator(const BaroOptions& options, uint64_t seed) : options_(options), seed_(seed) {}

double BaroSimulator::idealPressure(const TrajectoryState& st) const {
  const Eigen::Vector3d p_PinG = st.p_IinG + st.R_ItoG * options_.p_IP;
  return atmosphere::pressureFromHeight(p_PinG.z(), options_.reference_pressure_pa);
}

std::vector<BaroSample> BaroSimulator::simulate(const Trajectory& trajectory, double t_end_s) const {
  RandomStream rng(RandomStream::deriveSeed(seed_, "baro_noise"));
  const double dt = 1.0 / options_.rate_hz;
  const auto n = static_cast<int64_t>(std::floor(t_end_s / dt + 1e-9)) + 1;
  std::vector<BaroSample> out;
  out.reserve(static_cast<size_t>(n));
  for (int64_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * dt;
    out.push_back(draw(trajectory.evaluate(t), rng));
  }
  return out;
}

BaroSample BaroSimulator::draw(const TrajectoryState& state, RandomStream& rng) const {
  BaroSample s;
  s.t = Timestamp::fromSec(state.t_s);
  s.pressure_pa = idealPressure(state) + rng.gaussian(options_.pressure_sigma_pa);
  return s;
}

BaroSample BaroSimulator::sample(const TrajectoryState& state) {
  if (!rng_) rng_.emplace(RandomStream::deriveSeed(seed_, "baro_noise"));
  return draw(state, *rng_);
}

}  // namespace meshnav::sim
