/// @file peer_range_relay.cpp
/// @brief PeerRangeRelay: inter-vehicle ranges held until their vehicles' POSEs are there.

#include "pipeline/peer_range_relay.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace meshnav::pipeline {

void PeerRangeRelayOptions::validate() const {
  if (!(max_pose_age_s > 0.0) || !std::isfinite(max_pose_age_s))
    throw std::invalid_argument("PeerRangeRelayOptions: max_pose_age_s must be > 0 s");
  if (!(max_wait_s >= 0.0) || !std::isfinite(max_wait_s))
    throw std::invalid_argument("PeerRangeRelayOptions: max_wait_s must be >= 0 s");
  if (max_held < 1) throw std::invalid_argument("PeerRangeRelayOptions: max_held must be >= 1");
}

std::string PeerRangeRelayOptions::toString() const {
  std::ostringstream s;
  s << "a range waits up to " << max_wait_s << " s of data time for its vehicles' POSE, uses a pose within "
    << max_pose_age_s << " s of its instant, at most " << max_held << " wait";
  return s.str();
}

PeerRangeRelay::PeerRangeRelay(const std::vector<Vehicle>& vehicles, const SystemSetup& fleet_setup,
                               const PeerRangeRoutingOptions& routing, const PeerRangeRelayOptions& options,
                               Diagnostics& diag)
    : options_(options), diag_(diag), feed_(vehicles, fleet_setup, routing, diag), poses_(vehicles.size()) {
  options_.validate();
  if (vehicles.empty()) throw std::invalid_argument("PeerRangeRelay: no vehicle");
}

std::vector<PeerRangeFeed::Routed> PeerRangeRelay::onRange(size_t v, const RangeSample& r) {
  if (v >= poses_.size()) throw std::out_of_range("PeerRangeRelay: no vehicle " + std::to_string(v));
  noteDataTime(r.t);
  if (feed_.interVehicle(v, r)) {
    if (const auto ends = feed_.admit(r)) {
      if (static_cast<int>(held_.size()) >= options_.max_held) {
        diag_.count("inter_vehicle_range_hold_full");
        held_.pop_front();
      }
      // In time order (stable: an exchange of the same instant after those before it), so that
      // release() routes the oldest instant first: the router's provenance is a function of time.
      const auto at = std::upper_bound(held_.begin(), held_.end(), r.t,
                                       [](Timestamp t, const Held& h) { return t < h.range.t; });
      held_.insert(at, {r, *ends});
    }
  }
  return release();
}

std::vector<PeerRangeFeed::Routed> PeerRangeRelay::onPose(size_t v, const PoseEstimate& p) {
  std::deque<PoseEstimate>& poses = poses_.at(v);
  // In time order (a re-run may publish an instant again: the newer replaces it).
  auto it = std::lower_bound(poses.begin(), poses.end(), p.t, [](const PoseEstimate& a, Timestamp t) { return a.t < t; });
  if (it != poses.end() && it->t == p.t)
    *it = p;
  else
    poses.insert(it, p);
  // Kept: what a held range may still ask for (its wait plus the pose's age, and a margin).
  const Duration keep = Duration::fromSec(options_.max_wait_s + options_.max_pose_age_s + 1.0);
  while (poses.size() > 1 && poses.front().t < poses.back().t - keep) poses.pop_front();
  noteDataTime(p.t);
  return release();
}

void PeerRangeRelay::restoreAtFirstData(PeerRangeRouter::Provenance p, Timestamp written) {
  if (p.size() != poses_.size())
    throw std::invalid_argument("PeerRangeRelay::restoreAtFirstData: " + std::to_string(p.size()) + " vehicles, the fleet has " +
                                std::to_string(poses_.size()));
  pending_restore_ = PendingRestore{std::move(p), written};
}

void PeerRangeRelay::noteDataTime(Timestamp t) {
  if (!data_time_ || *data_time_ < t) data_time_ = t;
  if (!pending_restore_) return;
  const PendingRestore journal = std::move(*pending_restore_);
  pending_restore_.reset();
  const double age_s = (t - journal.written).sec();
  if (age_s < 0.0 || age_s > feed_.router().options().memory_s) {
    diag_.report("peer_router_state_not_used",
                 "peer_router: the provenance journal of t = " + formatSeconds(journal.written) + " s is not used at t = " +
                     formatSeconds(t) + " s: " + (age_s < 0.0 ? "it is of a later data time (another run's)" : "nothing in it counts any more (older than memory_s)"));
    return;
  }
  diag_.count("peer_router_state_restored", static_cast<int64_t>(feed_.router().restoreProvenance(journal.provenance, t)));
}

std::optional<PoseEstimate> PeerRangeRelay::poseNear(size_t v, Timestamp t) const {
  const std::deque<PoseEstimate>& poses = poses_[v];
  auto it = std::lower_bound(poses.begin(), poses.end(), t, [](const PoseEstimate& a, Timestamp x) { return a.t < x; });
  const PoseEstimate* best = nullptr;
  if (it != poses.end()) best = &*it;
  if (it != poses.begin()) {
    const PoseEstimate& before = *std::prev(it);
    if (!best || (t - before.t).sec() <= (best->t - t).sec()) best = &before;  // the earlier one at a tie
  }
  if (!best || std::abs((t - best->t).sec()) > options_.max_pose_age_s) return std::nullopt;
  return *best;
}

std::vector<PeerRangeFeed::Routed> PeerRangeRelay::release() {
  std::vector<PeerRangeFeed::Routed> out;
  if (held_.empty()) return out;
  const Duration wait = Duration::fromSec(options_.max_wait_s);
  for (auto it = held_.begin(); it != held_.end();) {
    const Timestamp t = it->range.t;
    const bool both = reached(it->ends.a, t) && reached(it->ends.b, t);
    const bool waited = data_time_ && *data_time_ - t >= wait;
    if (!both && !waited) {
      ++it;
      continue;
    }
    if (!both) diag_.count("inter_vehicle_range_pose_late");
    if (auto routed = feed_.route(it->range, it->ends, poseNear(it->ends.a, t), poseNear(it->ends.b, t)))
      out.push_back(std::move(*routed));
    it = held_.erase(it);
  }
  return out;
}

}  // namespace meshnav::pipeline
