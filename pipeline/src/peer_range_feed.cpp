#include "pipeline/peer_range_feed.h"

#include <stdexcept>

#include "common/skew.h"

namespace meshnav::pipeline {

PeerRangeFeed::PeerRangeFeed(const std::vector<Vehicle>& vehicles, const SystemSetup& fleet_setup,
                             const PeerRangeRoutingOptions& options, Diagnostics& diag)
    : vehicles_(vehicles), fleet_setup_(fleet_setup), diag_(diag), router_(options, vehicles.size()) {}

bool PeerRangeFeed::interVehicle(size_t v, const RangeSample& r) {
  const SystemSetup& mine = vehicles_.at(v).setup;
  const auto foreign = [&](SensorId id) { return fleet_setup_.isTag(id) && !mine.isTag(id); };
  if (foreign(r.id_initiator) || foreign(r.id_responder)) {
    diag_.count("inter_vehicle_range:" + vehicles_[v].name);
    return true;
  }
  // A range of this vehicle's tag to an anchor it can use (known or calibrated): its anchor count.
  const SensorId other = mine.isTag(r.id_initiator) ? r.id_responder : r.id_initiator;
  if ((mine.isTag(r.id_initiator) || mine.isTag(r.id_responder)) &&
      (fleet_setup_.isKnownAnchor(other) || calibrated_anchors_.count(other)))
    router_.noteAnchorRange(v, other, r.t);
  return false;
}

std::optional<PeerRangeFeed::Ends> PeerRangeFeed::admit(const RangeSample& r) {
  // Each range once: the same exchange may be logged by both vehicles (as the anchors' mesh is).
  constexpr int64_t kKeepUs = 10'000'000;
  while (!peer_ranges_.empty() && std::get<0>(*peer_ranges_.begin()) < r.t.us - kKeepUs)
    peer_ranges_.erase(peer_ranges_.begin());
  const auto key = pairKey(r.id_initiator, r.id_responder);
  if (!peer_ranges_.emplace(r.t.us, key.first, key.second).second) {
    diag_.count("inter_vehicle_range_duplicate");
    return std::nullopt;
  }
  // The two vehicles: whose tag is at each end.
  auto owner = [&](SensorId id) -> std::optional<size_t> {
    for (size_t k = 0; k < vehicles_.size(); ++k)
      if (vehicles_[k].setup.isTag(id)) return k;
    return std::nullopt;
  };
  const auto va = owner(r.id_initiator), vb = owner(r.id_responder);
  if (!va || !vb || *va == *vb) {
    diag_.count("inter_vehicle_range_not_between_two_vehicles");
    return std::nullopt;
  }
  return Ends{*va, *vb};
}

std::optional<PeerRangeFeed::Routed> PeerRangeFeed::route(const RangeSample& r, const Ends& ends,
                                                          const std::optional<PoseEstimate>& pa,
                                                          const std::optional<PoseEstimate>& pb) {
  // One of the two learns from the range, with the other's estimate as its anchor (never both:
  // each would count the other's information as independent of its own), and only where that
  // estimate holds nothing of the receiver's (PeerRangeRouter: from a vehicle with anchors to one
  // without, docs/decisions/016-fleet-sharing.md).
  PeerSide sa, sb;
  sa.has_estimate = pa.has_value();
  sb.has_estimate = pb.has_value();
  if (pa) sa.cov_p_trace_m2 = pa->cov_p_m2.trace();
  if (pb) sb.cov_p_trace_m2 = pb->cov_p_m2.trace();
  const PeerRangeRouter::Decision decision = router_.decide(ends.a, sa, ends.b, sb, r.t);
  if (!decision.receiver) {
    diag_.count("inter_vehicle_range_" + decision.why);
    return std::nullopt;
  }
  const bool to_a = *decision.receiver == ends.a;
  Routed out;
  out.receiver = to_a ? ends.a : ends.b;
  out.sender = to_a ? ends.b : ends.a;
  const PoseEstimate& ps = to_a ? *pb : *pa;
  const SensorId peer_tag = to_a ? r.id_responder : r.id_initiator;
  // The sender's tag at the range's instant (the header's model).
  const Eigen::Vector3d& l = leverArm(out.sender, peer_tag);
  const double dt = (r.t - ps.t).sec();
  const Eigen::Matrix3d R = ps.q_ItoG.toRotationMatrix();
  const Eigen::Matrix3d J = -R * skew(l);
  out.range.t = r.t;
  out.range.range = r;
  out.range.peer_tag = peer_tag;
  out.range.p_peer_tag_in_G = ps.p_IinG + dt * ps.v_IinG + R * l;
  out.range.cov_peer_tag_m2 = ps.cov_p_m2 + dt * dt * ps.cov_v + J * ps.cov_theta_rad2 * J.transpose();
  diag_.count("inter_vehicle_range_to:" + vehicles_[out.receiver].name);
  router_.noteReceived(out.receiver, out.sender, r.t);
  return out;
}

}  // namespace meshnav::pipeline
