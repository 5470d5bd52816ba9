/// @file range_residuals.cpp
/// @brief RangeResiduals (range_residuals.h).

#include "view/range_residuals.h"

#include <Eigen/Geometry>

#include <algorithm>

namespace meshnav::view {

RangeResiduals::RangeResiduals(AnchorLookup anchors, std::function<void(const RangeResidual&)> sink)
    : anchors_(std::move(anchors)), sink_(std::move(sink)) {}

namespace {
/// Tag and anchor of a tag–anchor range; false for any other pair.
bool tagAndAnchor(const RangeSample& r, SensorId& tag, SensorId& anchor) {
  if (r.type_initiator == UwbType::Tag && r.type_responder == UwbType::Anchor) {
    tag = r.id_initiator;
    anchor = r.id_responder;
    return true;
  }
  if (r.type_initiator == UwbType::Anchor && r.type_responder == UwbType::Tag) {
    tag = r.id_responder;
    anchor = r.id_initiator;
    return true;
  }
  return false;
}
}  // namespace

void RangeResiduals::onRange(const RangeSample& r) {
  SensorId tag = 0, anchor = 0;
  if (!tagAndAnchor(r, tag, anchor)) return;
  if (!poses_.empty() && poses_.back().t >= r.t) {
    evaluate(r, tag, anchor);
    return;
  }
  pending_.push_back(r);
  if (pending_.size() > kMaxPending) {
    pending_.pop_front();
    diag_.count("residual:pending_dropped");
  }
}

void RangeResiduals::onPose(const PoseEstimate& p) {
  if (!poses_.empty() && p.t < poses_.back().t) return;  // out of order: the history stays sorted
  poses_.push_back(p);
  while (poses_.size() > 2 && (p.t - poses_.front().t).sec() > kPoseHistory_s) poses_.pop_front();
  // Ranges at or before this pose can now be placed.
  std::deque<RangeSample> still;
  for (const RangeSample& r : pending_) {
    if (r.t <= p.t) {
      SensorId tag = 0, anchor = 0;
      tagAndAnchor(r, tag, anchor);
      evaluate(r, tag, anchor);
    } else {
      still.push_back(r);
    }
  }
  pending_.swap(still);
}

void RangeResiduals::evaluate(const RangeSample& r, SensorId tag, SensorId anchor) {
  const Eigen::Vector3d* p_AinG = anchors_(anchor);
  if (!p_AinG) {
    diag_.count("residual:no_anchor_position");
    return;
  }
  // The poses around r.t: the first at or after it, and the one before.
  auto after = std::lower_bound(poses_.begin(), poses_.end(), r.t,
                                [](const PoseEstimate& p, Timestamp t) { return p.t < t; });
  Eigen::Vector3d p_IinG;
  Eigen::Quaterniond q_ItoG;
  if (after == poses_.begin()) {
    p_IinG = after->p_IinG;
    q_ItoG = after->q_ItoG;
  } else if (after == poses_.end()) {
    p_IinG = poses_.back().p_IinG;
    q_ItoG = poses_.back().q_ItoG;
  } else {
    const PoseEstimate& a = *(after - 1);
    const PoseEstimate& b = *after;
    const double span = (b.t - a.t).sec();
    const double f = span > 0.0 ? (r.t - a.t).sec() / span : 1.0;
    p_IinG = (1.0 - f) * a.p_IinG + f * b.p_IinG;
    q_ItoG = a.q_ItoG.slerp(f, b.q_ItoG);
  }
  Eigen::Vector3d p_TinI = Eigen::Vector3d::Zero();
  if (auto it = lever_arms_.find(tag); it != lever_arms_.end()) p_TinI = it->second;
  const Eigen::Vector3d p_TinG = p_IinG + q_ItoG.normalized() * p_TinI;
  sink_({r.t, tag, anchor, r.range_m - (p_TinG - *p_AinG).norm()});
}

}  // namespace meshnav::view
