#pragma once
/// @file peer_range_router.h
/// @brief Which vehicle of a fleet fuses a range between two vehicles' tags, so that no vehicle
/// counts the same information twice (docs/decisions/016-fleet-sharing.md).
///
/// A range between tag T of vehicle A and tag S of vehicle B is fused in one vehicle, the
/// **receiver**, with the other's (the **sender's**) estimate of its tag as a point whose error is
/// independent of the receiver's state (EstimatorNode::processPeerRange adds β² uᵀ Σ_S u to R).
/// That is exact only when the sender's estimate holds nothing the receiver knows; the rule keeps
/// the flow of information acyclic so that it does:
///  - a vehicle **receives** only while it is **short of anchors**: fewer than `min_anchors`
///    distinct anchors (known or calibrated) ranged by its tags within the last `anchor_window_s`;
///  - a vehicle **sends** only while it is **clean**: it has received no peer range within the
///    last `memory_s` (the time after which its own anchor ranges, not the peers', make its
///    estimate; a bound, not exact: docs/decisions/016-fleet-sharing.md);
///  - both can receive from each other (both short, both clean): the one with the larger position
///    covariance trace; neither: the range is not fused (the reason is returned).
/// Information thus flows from vehicles with anchors to vehicles without, never back within
/// `memory_s`; two vehicles without anchors share nothing once either has received.

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
  double memory_s = 10.0;         ///< a receiver sends again this long after its last peer range [s]
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
  /// Vehicle `v` fused a peer range at `t` (it is not clean until t + memory_s).
  void noteReceived(size_t v, Timestamp t);

  /// Distinct anchors vehicle `v` ranged within (t − anchor_window_s, t].
  int anchorsSeen(size_t v, Timestamp t) const;
  bool shortOfAnchors(size_t v, Timestamp t) const { return anchorsSeen(v, t) < options_.min_anchors; }
  bool clean(size_t v, Timestamp t) const;

  struct Decision {
    std::optional<size_t> receiver;  ///< a or b; nullopt: not fused
    std::string why;                 ///< when not fused: "not_needed", "cycle" or "no_estimate"
  };
  /// The receiver of a range at `t` between vehicles a and b (a ≠ b).
  Decision decide(size_t a, const PeerSide& side_a, size_t b, const PeerSide& side_b, Timestamp t) const;

  const PeerRangeRoutingOptions& options() const { return options_; }

 private:
  PeerRangeRoutingOptions options_;
  std::vector<std::map<SensorId, Timestamp>> anchor_seen_;  ///< per vehicle: anchor -> last range
  std::vector<std::optional<Timestamp>> last_received_;      ///< per vehicle
};

}  // namespace meshnav::pipeline
