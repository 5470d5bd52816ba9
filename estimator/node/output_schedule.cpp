/// @file output_schedule.cpp
/// @brief OutputSchedule and the POSE / ANCHORS messages of the filter (output_schedule.h).

#include "estimator/node/output_schedule.h"

#include "estimator/smooth/fixed_lag_smoother.h"

#include <algorithm>

namespace meshnav::estimator {

PoseEstimate poseOf(const FusionStrategy& f) {
  const NominalState& x = f.state();
  return poseOfBelief(ImuBelief{x.t, x.imu, ImuMatrix(f.covariance(x.imu_id, x.imu_id))});
}

std::vector<AnchorEstimate> anchorsOf(const FusionStrategy& f, const UwbNetwork& network) {
  std::vector<AnchorEstimate> out;
  const NominalState& x = f.state();
  for (const auto& [id, p] : network.exactAnchors()) out.push_back({x.t, id, p, Eigen::Matrix3d::Zero()});
  for (const auto& [id, a] : x.values<AnchorKind>())
    out.push_back({x.t, id, a.p_AinG, f.covariance(id, id).topLeftCorner<3, 3>()});
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
  return out;
}

bool OutputSchedule::poseDue(Timestamp t) {
  const bool due = pose_rate_hz_ <= 0.0 || !last_pose_ || (t - *last_pose_).sec() >= 1.0 / pose_rate_hz_ - 1e-6;
  if (due) last_pose_ = t;
  return due;
}

bool OutputSchedule::periodDue(std::optional<Timestamp>& next, double rate_hz, Timestamp now) {
  if (next && now < *next) return false;
  const Duration period = Duration::fromSec(1.0 / rate_hz);
  next = (next && now - *next < period) ? *next + period : now + period;
  return true;
}

}  // namespace meshnav::estimator
