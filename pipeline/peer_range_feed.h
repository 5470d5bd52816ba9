#pragma once
/// @file peer_range_feed.h
/// @brief A fleet's ranges between two vehicles' tags, from the vehicles' data to the estimator
/// that fuses each (docs/fleet.md "Inter-vehicle ranges"), the same in one process
/// (pipeline::Pipeline, `meshnav_run --fleet`) and over LCM (`peer_router`, through
/// PeerRangeRelay). Free of LCM.
///
///  - **Which ranges**: a range of vehicle v's data with a tag of another vehicle at one end is an
///    inter-vehicle range (counted "inter_vehicle_range:<v>"); every other range of v's tags to an
///    anchor v can use (known, or calibrated: onAnchorInit) counts towards v's anchors
///    (PeerRangeRouter::noteAnchorRange).
///  - **Each exchange once**: both vehicles' data may hold the same range (same µs and pair);
///    the second is counted "inter_vehicle_range_duplicate" (kept 10 s).
///  - **One receiver**: PeerRangeRouter decides which vehicle fuses it (docs/decisions/016-fleet-sharing.md).
///  - **The sender's tag**: from the sender's pose at t_P, moved to the range's instant t with its
///    velocity, dt = t − t_P (either sign):
///        p_S = p_I + v dt + R l,   R = R̂ Exp(δθ)  ⇒  ∂p_S/∂δθ = −R̂ [l]×,
///        Σ_S = Σ_p + dt² Σ_v + J Σ_θ Jᵀ,  J = −R̂ [l]×
///    (the cross-covariances of p, v, θ are not on POSE and are left out). The acceleration over
///    dt is not modelled: ½ a dt², below 1 cm for |a| ≤ 8 m/s² and |dt| ≤ 50 ms, which is why a
///    caller gives a pose at most that far from t (PeerRangeRelay::Options::max_pose_age_s; in
///    one process the sender's pose is at most one input older).

#include <map>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "common/diagnostics.h"
#include "common/setup.h"
#include "common/types.h"
#include "pipeline/peer_range_router.h"
#include "pipeline/pipeline.h"

namespace meshnav::pipeline {

class PeerRangeFeed {
 public:
  /// Counters go to `diag`, which must outlive the feed. Throws std::invalid_argument for no
  /// vehicle or invalid routing options.
  PeerRangeFeed(const std::vector<Vehicle>& vehicles, const SystemSetup& fleet_setup,
                const PeerRangeRoutingOptions& options, Diagnostics& diag);

  size_t vehicleCount() const { return vehicles_.size(); }
  const std::string& vehicleName(size_t v) const { return vehicles_.at(v).name; }

  /// A range of vehicle `v`'s data: true when one end is another vehicle's tag (an inter-vehicle
  /// range, counted); otherwise, for a range of v's tag to an anchor v can use, v's anchor count.
  bool interVehicle(size_t v, const RangeSample& r);
  /// Anchor `id` was calibrated (an ANCHOR_INIT): from now on ranges to it count as anchor ranges.
  void onAnchorInit(SensorId id) { calibrated_anchors_.insert(id); }

  /// The two vehicles of an inter-vehicle range: `a` owns its initiator, `b` its responder.
  struct Ends {
    size_t a = 0;
    size_t b = 0;
  };
  /// The first sight of an inter-vehicle exchange: its two vehicles; nullopt (counted) for a
  /// duplicate or a range that does not join tags of two vehicles.
  std::optional<Ends> admit(const RangeSample& r);

  /// An inter-vehicle range to one estimator.
  struct Routed {
    size_t receiver = 0;  ///< the vehicle that fuses it
    size_t sender = 0;    ///< the vehicle whose estimate places the other tag
    PeerRange range;
  };
  /// Which of `ends` fuses `r` and with what (the header's model), given each vehicle's pose near
  /// r.t (nullopt: no estimate). Nullopt when neither may (counted "inter_vehicle_range_<why>");
  /// else counted "inter_vehicle_range_to:<receiver>" and noted in the router's provenance.
  std::optional<Routed> route(const RangeSample& r, const Ends& ends, const std::optional<PoseEstimate>& pose_a,
                              const std::optional<PoseEstimate>& pose_b);

  /// The routing rule and its provenance (a restart's journal reads and restores it).
  const PeerRangeRouter& router() const { return router_; }
  PeerRangeRouter& router() { return router_; }

  /// Tag `tag` of vehicle `v` in its IMU frame [m] (std::out_of_range when v has no such tag).
  const Eigen::Vector3d& leverArm(size_t v, SensorId tag) const {
    return vehicles_.at(v).setup.rel_tag_positions.at(tag);
  }

 private:
  std::vector<Vehicle> vehicles_;
  SystemSetup fleet_setup_;
  Diagnostics& diag_;
  PeerRangeRouter router_;
  std::set<SensorId> calibrated_anchors_;                          ///< ids of the ANCHOR_INITs so far
  std::set<std::tuple<int64_t, SensorId, SensorId>> peer_ranges_;  ///< (µs, ids) of the exchanges admitted
};

}  // namespace meshnav::pipeline
