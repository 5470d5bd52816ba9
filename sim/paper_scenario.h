#pragma once
/// @file paper_scenario.h
/// @brief Fixed geometry of the paper's flight hall (docs/scenarios.md): UWB tags on the UAV, anchors on
/// the walls, IMU/baro ids, the baro lever arm and the hall's extent.

#include <Eigen/Core>
#include <map>
#include <set>
#include <vector>

#include "common/types.h"
#include "sim/hall.h"

namespace meshnav::sim {

/// The hardware of the paper's experiment (`paper()`), or of a generated scenario with the same
/// structure (`scenario_builder.h`). Frames: G = hall (z up, floor at z = 0), I = IMU.
struct PaperScenario {
  SensorId imu_id = 1;
  SensorId baro_id = 2;
  /// Tag lever arms p_TinI [m].
  std::map<SensorId, Eigen::Vector3d> tags_p_TinI;
  /// All anchors p_AinG [m] (the truth).
  std::map<SensorId, Eigen::Vector3d> anchors_p_AinG;
  /// Anchors whose position the user knows (surveyed): 101–104.
  std::set<SensorId> known_anchor_ids;
  /// Barometer position in the IMU frame p_IP [m].
  Eigen::Vector3d baro_p_IP{0.0, 0.0, 0.05};
  /// Hall extent (axis-aligned box, G) [m]; the UAV flies well inside it.
  Eigen::Vector3d hall_min_m{-2.5, -4.2, 0.0};
  Eigen::Vector3d hall_max_m{3.0, 4.2, 8.2};

  Hall hall() const { return Hall{hall_min_m, hall_max_m}; }

  /// The paper's values.
  static PaperScenario paper();
  /// Every UWB device id (tags and anchors), sorted ascending (the TDMA order).
  std::vector<SensorId> uwbDeviceIds() const;
  bool isTag(SensorId id) const { return tags_p_TinI.count(id) > 0; }
  UwbType typeOf(SensorId id) const { return isTag(id) ? UwbType::Tag : UwbType::Anchor; }
};

}  // namespace meshnav::sim
