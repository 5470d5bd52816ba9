#include "eval/true_range_model.h"

#include <algorithm>

#include "common/pose_interpolation.h"

namespace meshnav::eval {

void TrueRangeModel::setTrajectory(std::vector<PoseSample> sorted_poses,
                                   std::map<SensorId, Eigen::Vector3d> p_TinI) {
  poses_ = std::move(sorted_poses);
  lever_arms_ = std::move(p_TinI);
}

void TrueRangeModel::setTrueRangeSamples(const std::vector<RangeSample>& true_ranges) {
  samples_.clear();
  for (const auto& r : true_ranges)
    samples_[pairKey(r.id_initiator, r.id_responder)].emplace_back(r.t, r.range_m);
  for (auto& [key, v] : samples_)
    std::stable_sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
}

std::optional<double> TrueRangeModel::trueRange(const RangeSample& r, TrueRangeMiss* miss) const {
  auto set = [&](TrueRangeMiss m) {
    if (miss) *miss = m;
  };
  set(TrueRangeMiss::None);
  const SensorId a = r.id_initiator, b = r.id_responder;
  const bool a_moves = r.type_initiator == UwbType::Tag;
  const bool b_moves = r.type_responder == UwbType::Tag;

  // 1. Both stationary.
  if (!a_moves && !b_moves) {
    auto pa = static_.find(a), pb = static_.find(b);
    if (pa == static_.end() || pb == static_.end()) {
      set(TrueRangeMiss::UnknownDevice);
      return std::nullopt;
    }
    return (pa->second - pb->second).norm();
  }
  if (a_moves && b_moves) {  // tag–tag: only through the trajectory if both lever arms are known
    auto la = lever_arms_.find(a), lb = lever_arms_.find(b);
    if (la == lever_arms_.end() || lb == lever_arms_.end()) {
      set(TrueRangeMiss::UnknownDevice);
      return std::nullopt;
    }
    // Both on the same rigid body: the distance is constant.
    return (la->second - lb->second).norm();
  }
  const SensorId tag = a_moves ? a : b;
  const SensorId anchor = a_moves ? b : a;
  auto pa = static_.find(anchor);

  // 2. Trajectory and lever arm.
  auto lever = lever_arms_.find(tag);
  if (!poses_.empty() && lever != lever_arms_.end() && pa != static_.end()) {
    const auto pose = interpolatePose(poses_, r.t, max_gap_);
    if (!pose) {
      set(TrueRangeMiss::TimeGap);
      return std::nullopt;
    }
    const Eigen::Vector3d p_TinG = pose->p_IinG + pose->q_ItoG * lever->second;
    return (p_TinG - pa->second).norm();
  }

  // 3. Published true distances, nearest in time.
  auto it = samples_.find(pairKey(tag, anchor));
  if (it == samples_.end() || it->second.empty()) {
    set(poses_.empty() ? TrueRangeMiss::NoTrajectory : TrueRangeMiss::UnknownDevice);
    return std::nullopt;
  }
  const auto& v = it->second;
  auto up = std::lower_bound(v.begin(), v.end(), r.t,
                             [](const std::pair<Timestamp, double>& s, Timestamp t) { return s.first < t; });
  std::optional<std::pair<Duration, double>> best;
  auto consider = [&](decltype(up) p) {
    const Duration dt{std::abs((p->first - r.t).us)};
    if (!best || dt < best->first) best = std::make_pair(dt, p->second);
  };
  if (up != v.end()) consider(up);
  if (up != v.begin()) consider(std::prev(up));
  if (!best || best->first > max_dt_) {
    set(TrueRangeMiss::TimeGap);
    return std::nullopt;
  }
  return best->second;
}

}  // namespace meshnav::eval
