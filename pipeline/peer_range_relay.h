#pragma once
/// @file peer_range_relay.h
/// @brief PeerRangeFeed where the vehicles' POSEs arrive as messages (`peer_router` over LCM,
/// docs/fleet.md "Inter-vehicle ranges over LCM"): late, out of order or not at all. Free of LCM.
///
/// In one process the pipeline routes an inter-vehicle range at once with each estimator's pose
/// of that moment. Over LCM a vehicle's POSE of the range's instant t comes after the range (its
/// estimator answers the range ~0.4 ms after it), late (an estimator behind its data), or never
/// (a dead estimator, a lost datagram). So a range is **held** until each of its two vehicles'
/// POSE stream has reached t (a POSE at or after t), or until the relay's data time (the newest
/// range or POSE of any vehicle) is `max_wait_s` past t; then each vehicle's pose nearest t is
/// taken if it is within `max_pose_age_s` of t (PeerRangeFeed's model: the acceleration over dt
/// is not modelled; ½ a dt² < 1 cm for |a| ≤ 8 m/s², |dt| ≤ 50 ms), else that vehicle counts as
/// having no estimate (PeerRangeRouter: it neither sends nor receives). A range routed after its
/// receiver's estimator has passed t is a late input there, re-applied within its out-of-sequence
/// window (estimator.yaml window_s, 1 s): `max_wait_s` must stay below it.
///
/// Counters (the feed's and): "inter_vehicle_range_pose_late" (routed at the end of the wait, a
/// vehicle's POSE stream not at t),
/// "inter_vehicle_range_hold_full" (dropped: more than `max_held` waiting).

#include <deque>
#include <vector>

#include "common/diagnostics.h"
#include "pipeline/peer_range_feed.h"

namespace meshnav::pipeline {

struct PeerRangeRelayOptions {
  double max_pose_age_s = 0.05;  ///< a pose farther than this from the range's instant is not used [s]
  double max_wait_s = 0.5;       ///< data time a range waits for its vehicles' POSE [s] (< estimator window_s)
  int max_held = 4096;           ///< ranges waiting at most; more are dropped, counted [-]
  /// Throws std::invalid_argument naming the bad field.
  void validate() const;
  std::string toString() const;
};

class PeerRangeRelay {
 public:
  /// Counters go to `diag`, which must outlive the relay. Throws std::invalid_argument for
  /// invalid options or no vehicle.
  PeerRangeRelay(const std::vector<Vehicle>& vehicles, const SystemSetup& fleet_setup,
                 const PeerRangeRoutingOptions& routing, const PeerRangeRelayOptions& options, Diagnostics& diag);

  /// A range of vehicle `v`'s data (its bus's RANGE): what it makes routable now (in time order).
  std::vector<PeerRangeFeed::Routed> onRange(size_t v, const RangeSample& r);
  /// A POSE of vehicle `v`: what it makes routable now (in time order).
  std::vector<PeerRangeFeed::Routed> onPose(size_t v, const PoseEstimate& p);
  /// An ANCHOR_INIT (any vehicle's): the anchor counts towards the vehicles' anchors from now on.
  void onAnchorInit(SensorId id) { feed_.onAnchorInit(id); }

  /// A restart's journal (peer_router_state.h): the provenance `p` written at data time
  /// `written`, taken at the first range or POSE from now on (PeerRangeRouter::restoreProvenance at
  /// that input's time; counted "peer_router_state_restored" per entry kept). Refused whole when
  /// that time is before `written` (the file is of a later data time than this stream: another
  /// run's) or more than memory_s after it (nothing in it counts any more): reported
  /// "peer_router_state_not_used". Throws std::invalid_argument when `p` is not of this fleet's size.
  void restoreAtFirstData(PeerRangeRouter::Provenance p, Timestamp written);
  /// Whether a journal given to restoreAtFirstData still waits for the first input.
  bool restorePending() const { return pending_restore_.has_value(); }

  size_t held() const { return held_.size(); }
  const PeerRangeFeed& feed() const { return feed_; }
  /// The newest range or POSE of any vehicle (data time), if any came.
  std::optional<Timestamp> dataTime() const { return data_time_; }

 private:
  struct Held {
    RangeSample range;
    PeerRangeFeed::Ends ends;
  };
  /// An input of data time t: the newest data time, and a pending journal taken at the first.
  void noteDataTime(Timestamp t);
  /// Routes every held range whose wait is over, oldest first.
  std::vector<PeerRangeFeed::Routed> release();
  /// Vehicle v's pose nearest t, if within max_pose_age_s.
  std::optional<PoseEstimate> poseNear(size_t v, Timestamp t) const;
  /// Whether vehicle v's POSE stream has reached t.
  bool reached(size_t v, Timestamp t) const { return !poses_[v].empty() && poses_[v].back().t >= t; }

  PeerRangeRelayOptions options_;
  Diagnostics& diag_;
  PeerRangeFeed feed_;
  std::vector<std::deque<PoseEstimate>> poses_;  ///< per vehicle, its recent POSEs in time order
  std::deque<Held> held_;                         ///< in time order of the ranges, oldest first
  std::optional<Timestamp> data_time_;            ///< the newest range or POSE of any vehicle
  struct PendingRestore {
    PeerRangeRouter::Provenance provenance;
    Timestamp written;
  };
  std::optional<PendingRestore> pending_restore_;  ///< restoreAtFirstData's, until the first input
};

}  // namespace meshnav::pipeline
