#pragma once
/// @file peer_range_router.h
/// @brief Which vehicle of a fleet fuses a range between two vehicles' tags, so that no vehicle
/// counts the same information twice (docs/decisions/016-fleet-sharing.md).
///
/// A range between tag T of vehicle A and tag S of vehicle B is fused in one vehicle, the
/// **receiver**, with the other's (the **sender's**) estimate of its tag as a point whose error is
/// independent of the receiver's state (EstimatorNode::processPeerRange adds β² uᵀ Σ_S u to R).
/// That is exact only when the sender's estimate holds nothing of the receiver's; the rule keeps
/// the flow of information acyclic so that it does:
///  - a vehicle **receives** only while it is **short of anchors**: fewer than `min_anchors`
///    distinct anchors (known or calibrated) ranged by its tags within the last `anchor_window_s`;
///  - a vehicle **sends** to x only while its estimate **holds nothing of x's**: the router keeps,
///    per vehicle, whose information it absorbed and when (receiving from y adds y and everything y
///    held, the provenance); an entry counts for `memory_s` after it entered (the time after which
///    the vehicle's own anchor ranges, not the peers', make its estimate; a bound, not exact:
///    docs/decisions/016-fleet-sharing.md);
///  - both can receive from each other (both short, neither holding the other's): the one with the
///    larger position covariance trace; neither: the range is not fused (the reason is returned).
/// Information thus flows from vehicles with anchors to vehicles without and never back to where it
/// came from within `memory_s`. (Until 2026-12-07 a vehicle that had received from anyone sent to
/// no one for `memory_s`: on seed 9's outage that refused the ranges of a neighbour that held
/// nothing of the vehicle without anchors, 0.378 m against 0.183 m now; docs/fleet.md.)

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/types.h"

namespace meshnav::pipeline {

struct PeerRangeRoutingOptions {
  int min_anchors = 3;            ///< fewer distinct anchors than this: short of anchors [-]
  double anchor_window_s = 1.0;   ///< window of the anchor count [s]
  double memory_s = 10.0;         ///< what a vehicle absorbed from another counts this long [s]
  /// Throws std::invalid_argument naming the bad field.
  void validate() const;
  std::string toString() const;
};

/// What one vehicle offers to a decision: whether it has an estimate, and its position covariance trace.
struct PeerSide {
  bool has_estimate = false;
  double cov_p_trace_m2 = 0.0;
};

class PeerRangeRouter {
 public:
  /// Throws std::invalid_argument for invalid options or no vehicle.
  PeerRangeRouter(const PeerRangeRoutingOptions& options, size_t n_vehicles);

  /// A range of vehicle `v`'s tag to anchor `anchor` (known or calibrated) at `t`.
  void noteAnchorRange(size_t v, SensorId anchor, Timestamp t);
  /// Vehicle `v` fused a peer range from `sender` at `t`: from then on (for memory_s) v holds the
  /// sender's information and everything the sender held.
  void noteReceived(size_t v, size_t sender, Timestamp t);

  /// Distinct anchors vehicle `v` ranged within (t − anchor_window_s, t].
  int anchorsSeen(size_t v, Timestamp t) const;
  bool shortOfAnchors(size_t v, Timestamp t) const { return anchorsSeen(v, t) < options_.min_anchors; }
  /// Whether vehicle y's estimate holds information of vehicle x at t (absorbed within memory_s).
  bool holds(size_t y, size_t x, Timestamp t) const;

  struct Decision {
    std::optional<size_t> receiver;  ///< a or b; nullopt: not fused
    std::string why;                 ///< when not fused: "not_needed", "cycle" or "no_estimate"
  };
  /// The receiver of a range at `t` between vehicles a and b (a ≠ b).
  Decision decide(size_t a, const PeerSide& side_a, size_t b, const PeerSide& side_b, Timestamp t) const;

  const PeerRangeRoutingOptions& options() const { return options_; }

  /// Per vehicle: whose information its estimate absorbed (directly or through another) -> the
  /// data time it entered. What a restart must keep (peer_router_state.h): without it a respawned
  /// router would send a vehicle's information back to it within memory_s.
  using Provenance = std::vector<std::map<size_t, Timestamp>>;
  const Provenance& provenance() const { return holds_; }
  /// Takes `p` (a journal's) as the provenance at data time `now`: entries that entered after `now`
  /// (a file of a later data time than this stream: not this run's) or more than memory_s before it
  /// (they count no more) are dropped, as is an entry of a vehicle about itself. Returns how many
  /// entries were kept. Throws std::invalid_argument when `p` is not of this fleet's size or names
  /// a vehicle index out of it.
  size_t restoreProvenance(const Provenance& p, Timestamp now);

 private:
  PeerRangeRoutingOptions options_;
  std::vector<std::map<SensorId, Timestamp>> anchor_seen_;  ///< per vehicle: anchor -> last range
  Provenance holds_;
};

}  // namespace meshnav::pipeline
