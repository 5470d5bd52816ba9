#include "common/pose_interpolation.h"

#include <algorithm>

namespace meshnav {

namespace {

template <typename T>
std::optional<std::pair<size_t, double>> bracket(const std::vector<T>& v, Timestamp t, Duration max_gap,
                                                 Duration max_extrapolation) {
  if (v.empty()) return std::nullopt;
  if (t <= v.front().t) {
    if (v.front().t - t > max_extrapolation) return std::nullopt;
    return std::make_pair(size_t{0}, 0.0);
  }
  if (t >= v.back().t) {
    if (t - v.back().t > max_extrapolation) return std::nullopt;
    return std::make_pair(v.size() - 1, 0.0);
  }
  auto it = std::upper_bound(v.begin(), v.end(), t, [](Timestamp a, const T& b) { return a < b.t; });
  const size_t i1 = static_cast<size_t>(it - v.begin());
  const size_t i0 = i1 - 1;
  const Duration gap = v[i1].t - v[i0].t;
  if (gap > max_gap) return std::nullopt;
  const double a = gap.us > 0 ? static_cast<double>((t - v[i0].t).us) / static_cast<double>(gap.us) : 0.0;
  return std::make_pair(i0, a);
}

}  // namespace

std::optional<PoseSample> interpolatePose(const std::vector<PoseSample>& v, Timestamp t, Duration max_gap,
                                          Duration max_extrapolation) {
  auto b = bracket(v, t, max_gap, max_extrapolation);
  if (!b) return std::nullopt;
  const auto [i0, a] = *b;
  if (a == 0.0 || i0 + 1 >= v.size()) return PoseSample{t, v[i0].p_IinG, v[i0].q_ItoG};
  const auto& s0 = v[i0];
  const auto& s1 = v[i0 + 1];
  return PoseSample{t, (1.0 - a) * s0.p_IinG + a * s1.p_IinG, s0.q_ItoG.slerp(a, s1.q_ItoG).normalized()};
}

std::optional<PoseEstimate> interpolateEstimate(const std::vector<PoseEstimate>& v, Timestamp t, Duration max_gap) {
  auto b = bracket(v, t, max_gap, Duration{0});
  if (!b) return std::nullopt;
  const auto [i0, a] = *b;
  if (a == 0.0 || i0 + 1 >= v.size()) {
    PoseEstimate e = v[i0];
    e.t = t;
    return e;
  }
  const auto& s0 = v[i0];
  const auto& s1 = v[i0 + 1];
  PoseEstimate e = a < 0.5 ? s0 : s1;
  e.t = t;
  e.p_IinG = (1.0 - a) * s0.p_IinG + a * s1.p_IinG;
  e.v_IinG = (1.0 - a) * s0.v_IinG + a * s1.v_IinG;
  e.q_ItoG = s0.q_ItoG.slerp(a, s1.q_ItoG).normalized();
  return e;
}

std::vector<PoseSample> toPoseSamples(const std::vector<PoseEstimate>& estimates) {
  std::vector<PoseSample> out;
  out.reserve(estimates.size());
  for (const auto& e : estimates) out.push_back({e.t, e.p_IinG, e.q_ItoG});
  return out;
}

}  // namespace meshnav
