#include "sim/simulation_options.h"

#include <sstream>
#include <stdexcept>

namespace meshnav::sim {

void SimulationOptions::validate() const {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("SimulationOptions: ") + what);
  };
  require(duration_scale > 0.05 && duration_scale <= 20.0, "duration_scale must be in (0.05, 20]");
  require(uwb.sigma_range_m >= 0.0 && uwb.sigma_range_m < 10.0, "sigma_range_m must be in [0, 10) m");
  require(uwb.outlier_fraction >= 0.0 && uwb.outlier_fraction <= 1.0, "outlier_fraction must be in [0, 1]");
  require(uwb.drop_fraction >= 0.0 && uwb.drop_fraction < 1.0, "drop_fraction must be in [0, 1)");
  require(uwb.outlier_min_m >= 0.0 && uwb.outlier_max_m >= uwb.outlier_min_m, "outlier range must be 0 <= min <= max");
  require(uwb.slot_s > 0.0, "slot_s must be > 0");
  require(imu.rate_hz > 0.0 && baro.rate_hz > 0.0, "sensor rates must be > 0");
  require(ground_truth_rate_hz > 0.0 && flight_state_rate_hz > 0.0, "output rates must be > 0");
  require(initial_pose_sigma_p_m >= 0.0 && initial_pose_sigma_yaw_deg >= 0.0, "initial pose sigmas must be >= 0");
  if (trajectory) trajectory->validate();
}

std::string SimulationOptions::toString() const {
  std::ostringstream s;
  s << "seed " << seed << ", duration scale " << duration_scale << ", initial pose "
    << (with_initial_pose ? "yes" : "no") << " (sigma " << initial_pose_sigma_p_m << " m, "
    << initial_pose_sigma_yaw_deg << " deg), reference pressure " << reference_pressure_mean_pa << " +- "
    << reference_pressure_spread_pa << " Pa, ground truth " << ground_truth_rate_hz << " Hz, flight state "
    << flight_state_rate_hz << " Hz\n"
    << imu.toString() << "\n"
    << baro.toString() << "\n"
    << uwb.toString() << "\n"
    << hardware.toString();
  if (trajectory) s << "\n" << trajectory->toString();
  return s.str();
}

}  // namespace meshnav::sim
