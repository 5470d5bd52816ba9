#include "estimator/filter/joint_set_bound.h"

#include <algorithm>
#include <utility>
#include <vector>

namespace meshnav::estimator {

int boundJointSetAnchors(FusionStrategy& f, SensorId joined, int max_anchors) {
  if (max_anchors <= 0) return 0;
  std::vector<std::pair<double, SensorId>> others;  // (trace Σ_pp, id) of the other anchors
  for (SensorId m : f.jointSetOf(joined))
    if (m != joined && f.state().values<AnchorKind>().count(m))
      others.emplace_back(f.covariance(m, m).topLeftCorner<3, 3>().trace(), m);
  const size_t keep = static_cast<size_t>(max_anchors - 1);
  if (others.size() <= keep) return 0;
  std::sort(others.begin(), others.end());  // most refined first
  const size_t leave = others.size() - keep;
  for (size_t i = 0; i < leave; ++i) f.leaveJointSet(others[i].second);
  return static_cast<int>(leave);
}

}  // namespace meshnav::estimator
