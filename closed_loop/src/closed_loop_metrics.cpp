#include "closed_loop/closed_loop_metrics.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace meshnav::closed_loop {

ClosedLoopMetrics computeMetrics(const ClosedLoopResult& r, const TruthTimeline& truth_at, const FlightEnd& end) {
  ClosedLoopMetrics m;
  m.duration_s = end.duration_s;
  m.crashed = end.crashed;
  m.crash_reason = end.crash_reason;
  m.landed = end.landed;
  m.mission_complete = end.mission_complete;
  m.failsafe_events = end.failsafe_events;
  if (m.landed) m.landed_within_m = (end.p_end - r.pad).head<2>().norm();

  // The first estimate of every POSE time (a re-run may publish a time again).
  std::unordered_map<int64_t, size_t> estimate_at;
  for (size_t i = 0; i < r.estimates.size(); ++i) estimate_at.emplace(r.estimates[i].t.us, i);
  double sum_e2 = 0.0;
  size_t n_e = 0;
  for (const auto& [t_us, idx] : estimate_at) {
    const auto it = truth_at.find(t_us);
    if (it == truth_at.end() || !it->second.airborne) continue;
    const double e = (r.estimates[idx].p_IinG - it->second.p).norm();
    sum_e2 += e * e;
    ++n_e;
    m.max_estimation_error_m = std::max(m.max_estimation_error_m, e);
  }
  m.estimation_rmse_m = n_e ? std::sqrt(sum_e2 / static_cast<double>(n_e)) : 0.0;

  double sum_t2 = 0.0;
  size_t n_t = 0, n_air = 0;
  for (const auto& s : r.samples) {
    n_air += s.airborne ? 1 : 0;
    if (!s.airborne || s.status.mode != controller::ControlMode::Flying) continue;
    if (s.status.phase != "takeoff" && s.status.phase != "waypoints" && s.status.phase != "return") continue;
    sum_t2 += (s.p_true - s.status.setpoint.p_IinG).squaredNorm();
    ++n_t;
  }
  m.tracking_rmse_m = n_t ? std::sqrt(sum_t2 / static_cast<double>(n_t)) : 0.0;
  if (r.samples.size() > 1) m.flight_time_s = static_cast<double>(n_air) * (r.samples[1].t_s - r.samples[0].t_s);

  // Anchors: the calibration's initial beliefs and the estimator's last ones.
  std::map<SensorId, AnchorResult> anchors;
  for (const auto& a : r.anchor_inits) {
    const auto it = r.truth.anchor_positions.find(a.id);
    if (it == r.truth.anchor_positions.end()) continue;
    anchors[a.id].id = a.id;
    anchors[a.id].initial_error_m = (a.p_AinG - it->second).norm();
  }
  for (const auto& a : r.final_anchors)
    if (anchors.count(a.id)) anchors[a.id].final_error_m = (a.p_AinG - r.truth.anchor_positions.at(a.id)).norm();
  double s0 = 0.0, s1 = 0.0;
  int n0 = 0, n1 = 0;
  for (const auto& [id, a] : anchors) {
    m.anchors.push_back(a);
    if (a.initial_error_m >= 0.0) s0 += a.initial_error_m, ++n0;
    if (a.final_error_m >= 0.0) s1 += a.final_error_m, ++n1;
  }
  if (n0) m.anchors_initial_mean_m = s0 / n0;
  if (n1) m.anchors_final_mean_m = s1 / n1;
  return m;
}

}  // namespace meshnav::closed_loop
