#include "estimator/health/health_monitor.h"

#include <fmt/format.h>

namespace meshnav::estimator {

const char* healthName(Health h) {
  switch (h) {
    case Health::Initializing: return "initializing";
    case Health::Ok: return "ok";
    case Health::Degraded: return "degraded";
    case Health::Lost: return "lost";
  }
  return "?";
}

HealthMonitor::HealthMonitor(const HealthOptions& options) : options_(options) {}

void HealthMonitor::reset(Timestamp t) {
  events_.clear();
  by_type_.clear();
  by_anchor_.clear();
  health_ = candidate_ = Health::Ok;
  reason_.clear();
  last_accepted_range_ = candidate_since_ = t;
}

void HealthMonitor::onUpdate(Timestamp t, const std::string& type, SensorId anchor, bool accepted, double nis) {
  events_.push_back({t, type, anchor, accepted, nis});
  account(events_.back(), +1);
  if (type == "range" && accepted && t > last_accepted_range_) last_accepted_range_ = t;
}

void HealthMonitor::account(const Event& e, int sign) {
  auto add = [&](HealthStats& h) {
    h.n += sign;
    if (e.accepted)
      h.nis_sum += sign * e.nis;
    else
      h.n_gated += sign;
  };
  add(by_type_[e.type]);
  if (e.anchor) add(by_anchor_[e.anchor]);
}

std::map<std::string, HealthStats> HealthMonitor::stats() const {
  std::map<std::string, HealthStats> s;
  for (const auto& [type, h] : by_type_)
    if (h.n > 0) s[type] = h;
  for (const auto& [id, h] : by_anchor_)
    if (h.n > 0) s["anchor " + std::to_string(id)] = h;
  return s;
}

Health HealthMonitor::assess(Timestamp t, double sigma_p, std::string* why) const {
  const HealthStats range = rangeStats();
  int gated_anchors = 0;
  for (const auto& [id, h] : by_anchor_)
    if (h.n >= 2 && h.gatedFraction() >= options_.lost_gated_fraction) ++gated_anchors;
  const double no_aiding_s = (t - last_accepted_range_).sec();
  if (sigma_p > options_.lost_sigma_p_m) {
    *why = fmt::format("position sigma {:.2f} m > {:.2f} m", sigma_p, options_.lost_sigma_p_m);
    return Health::Lost;
  }
  if (range.n >= options_.min_ranges && range.gatedFraction() >= options_.lost_gated_fraction &&
      gated_anchors >= options_.min_anchors) {
    *why = fmt::format("{} of {} ranges gated in {:.0f} s, on {} anchors", range.n_gated, range.n, options_.window_s,
                       gated_anchors);
    return Health::Lost;
  }
  if (no_aiding_s > options_.lost_no_aiding_s) {
    *why = fmt::format("no range accepted for {:.1f} s (no usable position aiding)", no_aiding_s);
    return Health::Lost;
  }
  if (range.n >= 4 && range.gatedFraction() >= options_.degraded_gated_fraction) {
    *why = fmt::format("{} of {} ranges gated in {:.0f} s", range.n_gated, range.n, options_.window_s);
    return Health::Degraded;
  }
  if (range.n - range.n_gated >= 4 && range.meanNis() > options_.degraded_mean_nis) {
    *why = fmt::format("mean range NIS {:.1f} (1 if consistent)", range.meanNis());
    return Health::Degraded;
  }
  if (no_aiding_s > options_.degraded_no_aiding_s) {
    *why = fmt::format("no range accepted for {:.1f} s", no_aiding_s);
    return Health::Degraded;
  }
  why->clear();
  return Health::Ok;
}

HealthStats HealthMonitor::rangeStats() const {
  const auto it = by_type_.find("range");
  return it != by_type_.end() ? it->second : HealthStats{};
}

bool HealthMonitor::acceptedRangesFit(Timestamp t) const {
  const HealthStats range = rangeStats();
  // Too few accepted ranges say nothing either way (MILUV: 2 of 4 in 4 s).
  const bool nis_ok = range.n - range.n_gated >= options_.min_ranges && range.meanNis() <= options_.degraded_mean_nis;
  return nis_ok && (t - last_accepted_range_).sec() <= options_.degraded_no_aiding_s;
}

bool HealthMonitor::evaluate(Timestamp t, double sigma_p_max_m) {
  const Timestamp oldest = t - Duration::fromSec(options_.window_s);
  while (!events_.empty() && events_.front().t < oldest) {
    account(events_.front(), -1);
    events_.pop_front();
  }
  std::string why;
  const Health h = assess(t, sigma_p_max_m, &why);
  if (h != candidate_) {
    candidate_ = h;
    candidate_since_ = t;
  }
  // Worse states are reported at once, better ones once they held for hold_s.
  const bool worse = static_cast<int>(h) > static_cast<int>(health_);
  const bool held = (t - candidate_since_).sec() >= options_.hold_s;
  if (h == health_ || (!worse && !held)) {
    if (h == health_) reason_ = why;
    return false;
  }
  health_ = h;
  reason_ = why;
  return true;
}

}  // namespace meshnav::estimator
