#pragma once
/// @file true_range_model.h
/// @brief True distance between the two devices of a range measurement, for range statistics.
///
/// Sources, tried in this order for a range (a, b):
///  1. both ends stationary with known true positions → ‖p_a − p_b‖ (anchor–anchor);
///  2. one end a tag with a known lever arm p_TinI and a ground-truth trajectory → the tag at the
///     interpolated pose, p_TinG = p_IinG + R_ItoG p_TinI, and ‖p_TinG − p_anchor‖ (simulated
///     datasets: groundtruth.csv + setup.yaml lever arms + truth.yaml anchors);
///  3. published true tag-to-anchor distances (real recording: true_ranges_t2a.csv) → the sample of
///     the unordered pair {tag, anchor} nearest in time, if within `max_dt`.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/types.h"

namespace meshnav::eval {

/// Why no true range could be given.
enum class TrueRangeMiss { None, UnknownDevice, NoTrajectory, TimeGap };

class TrueRangeModel {
 public:
  /// True positions of stationary devices (anchors) in G [m].
  void setStaticPositions(std::map<SensorId, Eigen::Vector3d> p_inG) { static_ = std::move(p_inG); }
  /// Ground truth of the IMU frame and the tags' lever arms p_TinI [m] (sorted poses).
  void setTrajectory(std::vector<PoseSample> sorted_poses, std::map<SensorId, Eigen::Vector3d> p_TinI);
  /// Published true distances (ranges' `range_m` is the true distance); sorted by time inside.
  void setTrueRangeSamples(const std::vector<RangeSample>& true_ranges);
  /// Largest time difference for the nearest-sample lookup of source 3 [s].
  void setMaxDt(double max_dt_s) { max_dt_ = Duration::fromSec(max_dt_s); }
  /// Largest gap of the trajectory that may be interpolated [s].
  void setMaxTrajectoryGap(double s) { max_gap_ = Duration::fromSec(s); }

  /// True distance for `r` [m]; nullopt (with the reason in `miss`, if given) when unknown.
  std::optional<double> trueRange(const RangeSample& r, TrueRangeMiss* miss = nullptr) const;

 private:
  std::map<SensorId, Eigen::Vector3d> static_;
  std::vector<PoseSample> poses_;
  std::map<SensorId, Eigen::Vector3d> lever_arms_;
  /// {tag, anchor} (smaller id first) → (time, true distance), sorted by time.
  std::map<std::pair<SensorId, SensorId>, std::vector<std::pair<Timestamp, double>>> samples_;
  Duration max_dt_ = Duration::fromSec(0.05);
  Duration max_gap_ = Duration::fromSec(0.2);
};

}  // namespace meshnav::eval
