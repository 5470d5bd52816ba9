#include "sim/simulation_options.h"

#include <cmath>
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
  require(uwb.nlos_excess == "uniform" || uwb.nlos_excess == "exponential", "nlos excess must be uniform or exponential");
  require(uwb.outlier_mean_m > 0.0, "outlier mean excess must be > 0 [m]");
  require(uwb.correlation_time_s >= 0.0 && uwb.correlation_time_s <= 60.0, "range correlation time must be in [0, 60] s");
  require(std::abs(uwb.time_offset_s) <= 1.0, "range time offset must be in [-1, 1] s");
  require(uwb.slot_s > 0.0, "slot_s must be > 0");
  require(imu.rate_hz > 0.0 && baro.rate_hz > 0.0, "sensor rates must be > 0");
  require(imu.scale_sigma >= 0.0 && imu.scale_sigma <= 0.1 && imu.misalignment_sigma_rad >= 0.0 &&
              imu.misalignment_sigma_rad <= 0.1,
          "IMU axis scale sigma and misalignment sigma must be in [0, 0.1] (fraction, rad)");
  require(imu.vibration_acc_m_s2 >= 0.0 && imu.vibration_acc_m_s2 <= 10.0 && imu.vibration_gyro_rad_s >= 0.0 &&
              imu.vibration_gyro_rad_s <= 1.0,
          "IMU vibration must be in [0, 10] m/s^2 and [0, 1] rad/s (--vibration in [0, ~16])");
  require(imu.rotor_min_hz > 0.0 && imu.rotor_max_hz >= imu.rotor_min_hz, "rotor frequencies must be > 0 and ordered");
  require(ground_truth_rate_hz > 0.0 && flight_state_rate_hz > 0.0, "output rates must be > 0");
  require(initial_pose_sigma_p_m >= 0.0 && initial_pose_sigma_yaw_deg >= 0.0, "initial pose sigmas must be >= 0");
  if (trajectory) trajectory->validate();
  require(n_tags >= 1 && n_tags <= 3, "n_tags (--tags) must be 1, 2 or 3");
  require(n_known_anchors >= 3 && n_known_anchors <= 5, "n_known_anchors (--known) must be 3, 4 or 5");
  require(n_unknown_anchors >= 0 && n_unknown_anchors <= 20, "n_unknown_anchors (--unknown) must be in [0, 20]");
  require(anchor_layout != AnchorLayoutKind::Paper || n_known_anchors + n_unknown_anchors <= 9,
          "the paper anchor layout (--anchor-layout paper) has 9 anchors: --known + --unknown must be <= 9");
  if (hall_size_m) {
    const Eigen::Vector3d& s = *hall_size_m;
    require(s.x() >= 3.0 && s.y() >= 3.0 && s.x() <= 100.0 && s.y() <= 100.0, "hall (--hall) X and Y must be in [3, 100] m");
    require(s.z() >= 2.5 && s.z() <= 30.0, "hall (--hall) Z must be in [2.5, 30] m");
  }
  require(tag_id_offset >= 0 && tag_id_offset <= 1000000 && tag_id_offset % 1000 == 0,
          "tag_id_offset must be a multiple of 1000 in [0, 1000000]");
  if (flight_region) {
    const Hall h = hall();
    require((flight_region->min_m - h.min_m).minCoeff() >= -1e-9 && (h.max_m - flight_region->max_m).minCoeff() >= -1e-9 &&
                (flight_region->size().array() >= 2.5).all(),
            "flight_region must lie inside the hall and be at least 2.5 m along each axis");
  }
  if (duration_s) require(*duration_s >= 30.0 && *duration_s <= 3600.0, "duration_s (--duration) must be in [30, 3600] s");
}

bool SimulationOptions::isPaperScenario() const {
  return trajectory_kind == TrajectoryKind::Spiral && !hall_size_m && !flight_region && mesh_ranges && anchor_layout == AnchorLayoutKind::Paper &&
         n_tags == 2 && n_known_anchors == 4 && n_unknown_anchors == 5 && tag_id_offset == 0;
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
  s << "\nscenario: trajectory " << sim::toString(trajectory_kind) << ", " << hall().toString() << ", anchor layout "
    << sim::toString(anchor_layout) << ", " << n_tags << " tags, " << n_known_anchors << " known + " << n_unknown_anchors
    << " unknown anchors, duration ";
  if (duration_s) s << *duration_s << " s";
  else s << "140 s x duration scale";
  return s.str();
}

}  // namespace meshnav::sim
