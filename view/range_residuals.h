#pragma once
/// @file range_residuals.h
/// @brief Per-anchor range residuals for the view: r = z − ‖p_TinG − p_AinG‖, the measured range
/// z of a tag–anchor RANGE against the distance from the estimated tag position to the anchor
/// position the view holds, with p_TinG = p_IinG(t) + R_ItoG(t) p_TinI at the range's instant t.
///
/// p_IinG(t) is interpolated linearly between the two POSE messages around t, R_ItoG(t) by slerp
/// (a range is usually on the bus before the POSE that fused it, so it waits until a POSE at or
/// after t has come; one older than every kept pose uses the oldest). The tag lever arm p_TinI is
/// setup.yaml's when the view was given the setup, else zero (the residual then also holds the lever
/// arm's projection, up to its length). The range bias model (β, γ of the pair) is not applied: r
/// is what the filter sees before its bias states, so a calibrated pair's γ shows as an offset.
/// Ranges between two anchors or two tags give no residual.
///
/// Counters (diagnostics()): "residual:no_anchor_position" (an anchor the view has no position of
/// yet), "residual:pending_dropped" (more than kMaxPending ranges waited for a pose).

#include <deque>
#include <functional>
#include <map>
#include <vector>

#include <Eigen/Core>

#include "common/diagnostics.h"
#include "common/types.h"

namespace meshnav::view {

struct RangeResidual {
  Timestamp t;             ///< instant of the range
  SensorId tag = 0;
  SensorId anchor = 0;
  double residual_m = 0.0;  ///< z − ‖p_TinG − p_AinG‖ [m]
};

class RangeResiduals {
 public:
  /// Ranges kept while waiting for a pose at or after their instant.
  static constexpr size_t kMaxPending = 2000;
  /// Poses kept for the interpolation [s of data time before the newest].
  static constexpr double kPoseHistory_s = 2.0;

  /// The anchor's position in G, or nullptr when the view has none.
  using AnchorLookup = std::function<const Eigen::Vector3d*(SensorId)>;

  RangeResiduals(AnchorLookup anchors, std::function<void(const RangeResidual&)> sink);

  /// p_TinI of each tag (setup.yaml); a tag not listed has a zero lever arm.
  void setLeverArms(const std::map<SensorId, Eigen::Vector3d>& p_TinI) { lever_arms_ = p_TinI; }
  bool hasLeverArms() const { return !lever_arms_.empty(); }

  void onRange(const RangeSample& r);
  void onPose(const PoseEstimate& p);

  size_t pending() const { return pending_.size(); }
  const Diagnostics& diagnostics() const { return diag_; }

 private:
  /// The residual of `r` against the kept poses (at least one), handed to the sink.
  void evaluate(const RangeSample& r, SensorId tag, SensorId anchor);

  AnchorLookup anchors_;
  std::function<void(const RangeResidual&)> sink_;
  std::map<SensorId, Eigen::Vector3d> lever_arms_;
  std::deque<PoseEstimate> poses_;  ///< in time order
  std::deque<RangeSample> pending_;
  Diagnostics diag_;
};

}  // namespace meshnav::view
