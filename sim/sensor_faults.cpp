#include "sim/sensor_faults.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace meshnav::sim {

std::string SensorFaultOptions::toString() const {
  if (!any()) return "none";
  std::ostringstream s;
  for (const auto& [a, b] : imu_gaps_s) s << "IMU gap " << a << "-" << b << " s; ";
  if (anchor_off) s << "anchor " << *anchor_off << " off from " << anchor_off_from_s << " s; ";
  if (range_loss_fraction > 0.0)
    s << 100.0 * range_loss_fraction << " % RANGE loss from " << range_loss_from_s << " s; ";
  std::string out = s.str();
  return out.substr(0, out.size() - 2);
}

void SensorFaultOptions::validate() const {
  for (const auto& [a, b] : imu_gaps_s)
    if (!(b > a) || a < 0.0)
      throw std::invalid_argument("IMU gap " + std::to_string(a) + "," + std::to_string(b) +
                                  ": needs 0 <= from < to [s]");
  if (!(range_loss_fraction >= 0.0 && range_loss_fraction < 1.0))
    throw std::invalid_argument("RANGE loss fraction " + std::to_string(range_loss_fraction) + ": needs [0, 1)");
  if (anchor_off_from_s < 0.0 || range_loss_from_s < 0.0) throw std::invalid_argument("fault times must be >= 0 s");
}

SensorFaults::SensorFaults(SensorFaultOptions options, uint64_t seed)
    : options_(std::move(options)), rng_(RandomStream::deriveSeed(seed, "range_loss")) {
  options_.validate();
}

bool SensorFaults::imuLost(Timestamp t) const {
  const double s = t.sec();
  for (const auto& [a, b] : options_.imu_gaps_s)
    if (s >= a && s < b) return true;
  return false;
}

void SensorFaults::apply(VehicleOutputs& out) {
  if (!options_.any()) return;
  if (!options_.imu_gaps_s.empty()) {
    const size_t before = out.imu.size();
    std::erase_if(out.imu, [&](const ImuSample& s) { return imuLost(s.t); });
    imu_dropped_ += static_cast<int64_t>(before - out.imu.size());
  }
  std::erase_if(out.ranges, [&](const SimulatedRange& r) {
    const double t = r.sample.t.sec();
    if (options_.anchor_off && t >= options_.anchor_off_from_s &&
        (r.sample.id_initiator == *options_.anchor_off || r.sample.id_responder == *options_.anchor_off)) {
      ++ranges_anchor_off_;
      return true;
    }
    if (options_.range_loss_fraction > 0.0 && t >= options_.range_loss_from_s &&
        rng_.uniform() < options_.range_loss_fraction) {
      ++ranges_lost_;
      return true;
    }
    return false;
  });
}

}  // namespace meshnav::sim
