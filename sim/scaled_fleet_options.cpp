/// @file scaled_fleet_options.cpp
/// @brief ScaledFleetOptions: defaults, checks, print.

#include "sim/scaled_fleet_options.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace meshnav::sim {

Eigen::Vector3d ScaledFleetOptions::hallSize() const { return base.hall_size_m.value_or(Eigen::Vector3d(40.0, 40.0, 10.0)); }

int ScaledFleetOptions::flyByCount() const {
  return n_fly_by >= 0 ? n_fly_by : static_cast<int>(std::lround(0.2 * n_anchors));
}

void ScaledFleetOptions::validate() const {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("scaled fleet: " + what);
  };
  require(n_vehicles >= 1 && n_vehicles <= 16, "--vehicles must be 1-16");
  require(n_anchors >= 4 && n_anchors <= 400, "--anchors must be 4-400");
  require(flyByCount() >= 0 && flyByCount() <= n_anchors - 3, "--fly-by must be 0 to --anchors - 3");
  require(region_fraction >= 0.2 && region_fraction <= 1.0, "region fraction must be in [0.2, 1]");
  require(calibrate_at_fraction > 0.0 && calibrate_at_fraction < calibrate_again_at_fraction &&
              calibrate_again_at_fraction < 1.0,
          "calibration fractions must satisfy 0 < first < second < 1");
  if (outage.vehicle >= 0) {
    require(outage.vehicle < n_vehicles, "--outage names vehicle " + std::to_string(outage.vehicle) + " of " +
                                             std::to_string(n_vehicles));
    require(std::isfinite(outage.t0_s) && std::isfinite(outage.t1_s) && outage.t0_s >= 0.0 && outage.t1_s > outage.t0_s,
            "--outage needs 0 <= T0 < T1");
  }
  require(base.uwb.correlation_time_s == 0.0, "--range-correlation is not simulated in TDMA cells");
  tdma.validate();
  SimulationOptions probe = base;
  probe.hall_size_m = hallSize();
  probe.validate();
}

std::string ScaledFleetOptions::toString() const {
  std::ostringstream s;
  const Eigen::Vector3d h = hallSize();
  s << "scaled fleet: " << n_vehicles << " vehicles, " << n_anchors << " anchors (" << flyByCount() << " fly-by) in a "
    << h.x() << " x " << h.y() << " x " << h.z() << " m hall, flight regions " << region_fraction
    << " of the hall, fly-by calibration at " << calibrate_at_fraction << " and " << calibrate_again_at_fraction
    << " of the flight; " << tdma.toString();
  if (outage.vehicle >= 0)
    s << "; anchors silent for vehicle " << outage.vehicle << " from " << outage.t0_s << " to " << outage.t1_s << " s";
  return s.str();
}

}  // namespace meshnav::sim
