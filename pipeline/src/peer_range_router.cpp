/// @file peer_range_router.cpp
/// @brief PeerRangeRouter: the acyclic choice of the vehicle that fuses an inter-vehicle range.

#include "pipeline/peer_range_router.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace meshnav::pipeline {

void PeerRangeRoutingOptions::validate() const {
  if (min_anchors < 0) throw std::invalid_argument("PeerRangeRoutingOptions: min_anchors must be >= 0");
  if (!(anchor_window_s > 0.0) || !std::isfinite(anchor_window_s))
    throw std::invalid_argument("PeerRangeRoutingOptions: anchor_window_s must be > 0 s");
  if (!(memory_s >= 0.0) || !std::isfinite(memory_s))
    throw std::invalid_argument("PeerRangeRoutingOptions: memory_s must be >= 0 s");
}

std::string PeerRangeRoutingOptions::toString() const {
  std::ostringstream s;
  s << "peer ranges: received while fewer than " << min_anchors << " anchors in " << anchor_window_s
    << " s, sent to a vehicle whose information the sender did not absorb within " << memory_s << " s";
  return s.str();
}

PeerRangeRouter::PeerRangeRouter(const PeerRangeRoutingOptions& options, size_t n_vehicles)
    : options_(options), anchor_seen_(n_vehicles), holds_(n_vehicles) {
  options_.validate();
  if (n_vehicles == 0) throw std::invalid_argument("PeerRangeRouter: no vehicle");
}

void PeerRangeRouter::noteAnchorRange(size_t v, SensorId anchor, Timestamp t) {
  Timestamp& last = anchor_seen_.at(v)[anchor];
  if (last < t) last = t;
}

void PeerRangeRouter::noteReceived(size_t v, size_t sender, Timestamp t) {
  auto& h = holds_.at(v);
  auto enter = [&](size_t u) {
    if (u == v) return;
    auto [it, inserted] = h.emplace(u, t);
    if (!inserted && it->second < t) it->second = t;
  };
  enter(sender);
  // What the sender holds now enters v with it (a bound: it counts from t, not from when it
  // entered the sender).
  for (const auto& [u, since] : holds_.at(sender))
    if ((t - since).sec() <= options_.memory_s) enter(u);
}

int PeerRangeRouter::anchorsSeen(size_t v, Timestamp t) const {
  int n = 0;
  for (const auto& [id, last] : anchor_seen_.at(v))
    if ((t - last).sec() < options_.anchor_window_s) ++n;
  return n;
}

bool PeerRangeRouter::holds(size_t y, size_t x, Timestamp t) const {
  const auto& h = holds_.at(y);
  const auto it = h.find(x);
  return it != h.end() && (t - it->second).sec() <= options_.memory_s;
}

size_t PeerRangeRouter::restoreProvenance(const Provenance& p, Timestamp now) {
  if (p.size() != holds_.size())
    throw std::invalid_argument("PeerRangeRouter::restoreProvenance: " + std::to_string(p.size()) + " vehicles, the fleet has " +
                                std::to_string(holds_.size()));
  Provenance kept(holds_.size());
  size_t n = 0;
  for (size_t v = 0; v < p.size(); ++v) {
    for (const auto& [u, since] : p[v]) {
      if (u >= holds_.size())
        throw std::invalid_argument("PeerRangeRouter::restoreProvenance: vehicle index " + std::to_string(u) + " of " +
                                    std::to_string(holds_.size()));
      if (u == v || since > now || (now - since).sec() > options_.memory_s) continue;
      kept[v].emplace(u, since);
      ++n;
    }
  }
  holds_ = std::move(kept);
  return n;
}

PeerRangeRouter::Decision PeerRangeRouter::decide(size_t a, const PeerSide& side_a, size_t b, const PeerSide& side_b,
                                                  Timestamp t) const {
  // x can receive from y: x needs it, y's estimate exists and holds nothing of x's.
  auto can = [&](size_t x, const PeerSide& sx, size_t y, const PeerSide& sy) {
    return sx.has_estimate && sy.has_estimate && shortOfAnchors(x, t) && !holds(y, x, t);
  };
  const bool to_a = can(a, side_a, b, side_b), to_b = can(b, side_b, a, side_a);
  Decision d;
  if (to_a && to_b)
    d.receiver = side_a.cov_p_trace_m2 >= side_b.cov_p_trace_m2 ? a : b;
  else if (to_a)
    d.receiver = a;
  else if (to_b)
    d.receiver = b;
  else if (!side_a.has_estimate || !side_b.has_estimate)
    d.why = "no_estimate";
  else if (!shortOfAnchors(a, t) && !shortOfAnchors(b, t))
    d.why = "not_needed";
  else
    d.why = "cycle";
  return d;
}

}  // namespace meshnav::pipeline
