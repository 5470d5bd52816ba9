/// @file estimator_node_updates.cpp
/// @brief EstimatorNode, the measurement updates: baro (height from pressure against the reference
/// taken at the first sample), height above the floor, UWB range and anchor initialization, each
/// counted per sensor. The first part, estimator_node.cpp, holds input handling, processing and
/// outputs.

#include <spdlog/spdlog.h>

#include <cmath>

#include "common/atmosphere.h"
#include "estimator/node/estimator_node.h"
#include "estimator/node/node_internals.h"
#include "estimator/zupt/rest_measurement.h"

namespace meshnav::estimator {

using node_internal::where;

void EstimatorNode::processBaro(const BaroSample& s, bool first) {
  if (!sensors_.baro.enabled()) return;
  if (!sensors_.baro.reference()) {
    event(first, "baro_no_reference");
    return;
  }
  propagateTo(s.t);
  ScopedStepTimer timer(timings_, "baro_update");
  const UpdateResult r = sensors_.baro.update(*cur_.filter, s);
  if (first) countScalarUpdate(s.t, setup_.baro_id, "baro", r);
}

void EstimatorNode::countScalarUpdate(Timestamp t, SensorId id, const std::string& type, const UpdateResult& r) {
  InstanceStatus& st = instance_stats_[id];
  health_.onUpdate(t, type, 0, r.accepted, r.nis);
  if (r.accepted) {
    ++st.n_updates;
  } else {
    ++st.n_rejected;
    diag_.count("gated_" + type);
  }
}

void EstimatorNode::processHeight(const HeightSample& s, bool first) {
  if (!sensors_.height.enabled()) return;
  if (const std::string why = sensors_.height.refusal(*cur_.filter, s); !why.empty()) {
    if (why == "height_id_is_an_anchor")
      event(first, why,
            where("HEIGHT", s.t) + ": height_id " + std::to_string(setup_.height_id) +
                " is an estimated anchor's id; heights not used (set height_id in setup.yaml)");
    else
      event(first, why);
    return;
  }
  sensors_.height.ensureBiasState(*cur_.filter, s.t, first);
  propagateTo(s.t);
  ScopedStepTimer timer(timings_, "height_update");
  const UpdateResult r = sensors_.height.update(*cur_.filter, s);
  if (first) countScalarUpdate(s.t, setup_.height_id, sensors_.height.typeName(), r);
}

void EstimatorNode::processRange(const RangeSample& s, bool first) {
  if (!sensors_.range.enabled()) return;
  RangeMeasurement z = sensors_.range.measurement(s);
  if (cur_.last_imu) z.omega_IinI_rad_s = cur_.last_imu->gyro_rad_s;  // the body rate at t (range_model.h)
  if (const std::string why = sensors_.range.refusal(z, *cur_.filter, *cur_.network); !why.empty()) {
    if (why == "unknown_id")
      event(first, why,
            where("RANGE", s.t) + ": unknown device in range " + std::to_string(z.a) + "–" + std::to_string(z.b));
    else
      event(first, why);
    return;
  }
  propagateTo(s.t);
  ScopedStepTimer timer(timings_, "range_update");
  std::string why;
  const std::optional<Linearization> linearized = sensors_.range.linearize(z, *cur_.filter, *cur_.network, &why);
  if (!linearized) {
    event(first, why);
    return;
  }
  Linearization lin = *linearized;
  // Correlated errors: a range soon after its pair's previous one carries less new information;
  // the step weights it so, the gate and the NIS judge it by its own error (Linearization).
  lin.step_noise_factor = cur_.range_errors.inflation(z.a, z.b, s.t);
  const bool tag_range = cur_.network->isTag(z.a) || cur_.network->isTag(z.b);
  bool count = first;
  if (tag_range &&
      !reentry_.admit(s, cur_.network->isTag(z.a) ? z.b : z.a, lin, *cur_.filter, timeline_.start(), first, &count))
    return;
  const UpdateResult r = sensors_.range.update(*cur_.filter, lin);
  cur_.range_errors.noteRange(z.a, z.b, s.t);  // fused or gated: the error process went on
  const double prior_ratio = RangeUpdater::priorRatio(lin, r);
  const long decisions = cur_.noise_adapter.decisions();
  if (tag_range && cur_.noise_adapter.onRangeNis(r.nis, prior_ratio, r.accepted) && first) {
    diag_.count("process_noise_scale_change");
    spdlog::info("estimator: IMU noise scale {:.3g} at t={} (median range NIS {:.2f} of its expected value)",
                 cur_.noise_adapter.scale(), formatSeconds(s.t), cur_.noise_adapter.lastRatio());
  }
  // Every batch's median NIS, whether λ changed or not (it holds at its bound, or while H P Hᵀ ≫ R).
  if (first && cur_.noise_adapter.decisions() != decisions) gravity_.noteRangeNisRatio(cur_.noise_adapter.lastRatio());
  if (!count) {
    if (!first) recountRange(s, z.a, z.b, r.accepted);
    return;
  }
  range_fates_[inputOrder(s)] = r.accepted;
  if (!r.accepted) diag_.count("gated_range");
  if (tag_range && r.accepted) reentry_.noteAccepted(s.t);
  // Tag ranges tell whether the pose is right; ranges between anchors do not.
  if (tag_range) {
    health_.onUpdate(s.t, "range", cur_.network->isTag(z.a) ? z.b : z.a, r.accepted, r.nis);
    recovery_confirmation_.noteRange(r.accepted, r.nis);
  } else {
    health_.onUpdate(s.t, "anchor_range", 0, r.accepted, r.nis);
  }
  for (SensorId id : {z.a, z.b}) {
    InstanceStatus& is = instance_stats_[id];
    ++(r.accepted ? is.n_updates : is.n_rejected);
  }
}

void EstimatorNode::recountRange(const RangeSample& s, SensorId a, SensorId b, bool accepted) {
  auto it = range_fates_.find(inputOrder(s));
  if (it == range_fates_.end() || it->second == accepted) return;
  // A rewind re-processed this range with the other decision (a late input before it changed the
  // state): the instances' counts follow its last decision, as in-order processing would count it.
  it->second = accepted;
  for (SensorId id : {a, b}) {
    InstanceStatus& is = instance_stats_[id];
    --(accepted ? is.n_rejected : is.n_updates);
    ++(accepted ? is.n_updates : is.n_rejected);
  }
}

void EstimatorNode::processPeerRange(const PeerRange& p, bool first) {
  if (!sensors_.range.enabled()) return;
  const SensorId own = p.range.id_initiator == p.peer_tag ? p.range.id_responder : p.range.id_initiator;
  const bool ends = (p.range.id_initiator == p.peer_tag) != (p.range.id_responder == p.peer_tag);
  // (Its values were checked by the input gate: input_gate.cpp.) The ends: one of this vehicle's
  // tags and a device this vehicle does not know otherwise.
  if (!ends || !cur_.network->isTag(own) || cur_.network->isTag(p.peer_tag) || cur_.network->exactAnchor(p.peer_tag) ||
      cur_.filter->state().values<AnchorKind>().count(p.peer_tag)) {
    event(first, "peer_range_invalid",
          where("PEER_RANGE", p.t) + ": range " + std::to_string(p.range.id_initiator) + "–" +
              std::to_string(p.range.id_responder) + " is not between a tag of this vehicle and peer tag " +
              std::to_string(p.peer_tag) + " (a device this vehicle does not know otherwise)");
    return;
  }
  // The peer's tag, for this update only, as an exactly known point where its vehicle's estimate
  // puts it; its uncertainty enters R below. A copy: the network the filter keeps is not touched.
  UwbNetwork with_peer = *cur_.network;
  with_peer.setExactAnchor(p.peer_tag, p.p_peer_tag_in_G);
  // A tag pair of two vehicles is an uncalibrated pair unless setup.yaml lists it: γ 0 with the
  // uncalibrated pairs' σ_γ in R, as for a tag and an anchor the setup does not list.
  if (!with_peer.hasPairBias(own, p.peer_tag)) {
    PairBias b;
    b.a = own;
    b.b = p.peer_tag;
    b.sigma_m = 0.0;  // the range σ from rangeSigma's fallbacks
    b.sigma_gamma_m = options_.uwb.uncalibratedPairSigma();
    with_peer.setPairBias(b);
  }
  RangeMeasurement z = sensors_.range.measurement(p.range);
  if (cur_.last_imu) z.omega_IinI_rad_s = cur_.last_imu->gyro_rad_s;
  if (const std::string why = sensors_.range.refusal(z, *cur_.filter, with_peer); !why.empty()) {
    event(first, "peer_range_" + why);
    return;
  }
  propagateTo(p.t);
  ScopedStepTimer timer(timings_, "peer_range_update");
  std::string why;
  std::optional<Linearization> lin = sensors_.range.linearize(z, *cur_.filter, with_peer, &why);
  if (!lin) {
    event(first, "peer_range_" + why);
    return;
  }
  // z = β‖p_T − p_S‖ + γ + ν with p_S ~ N(p̂_S, Σ_S) independent of this vehicle's state:
  // ∂z/∂p_S = β uᵀ = −∂z/∂p_IinG, so the point's error adds β² uᵀ Σ_S u = H_p Σ_S H_pᵀ to R.
  const SensorId imu = cur_.filter->state().imu_id;
  for (const JacobianBlock& b : lin->blocks)
    if (b.id == imu) {
      const Eigen::RowVector3d H_p = b.H.block<1, 3>(0, ImuErr::kP);
      lin->R(0, 0) += H_p * p.cov_peer_tag_m2 * H_p.transpose();
    }
  const UpdateResult r = sensors_.range.update(*cur_.filter, *lin);
  if (!first) return;
  diag_.count(r.accepted ? "peer_range_fused" : "peer_range_gated");
  // A peer range that fits says the pose is right as a tag–anchor range does: without it a
  // vehicle among its peers but out of the anchors' reach was declared lost and re-initialized
  // from too few ranges (5 m off, docs/fleet.md).
  health_.onUpdate(p.t, "range", p.peer_tag, r.accepted, r.nis);
  InstanceStatus& is = instance_stats_[p.peer_tag];
  ++(r.accepted ? is.n_updates : is.n_rejected);
}

void EstimatorNode::applyAnchorInit(const AnchorInit& a, bool first) {
  if (const std::string why = sensors_.anchor_join.apply(a, *cur_.filter, cur_.network, first); !why.empty())
    event(first, "bad_command", where("ANCHOR_INIT", a.t) + ": id " + std::to_string(a.id) + why);
}

/// Zero-velocity update at the IMU reading `s` while landed (rate `zupt.rate_hz`; restMeasurement).
void EstimatorNode::processZupt(const ImuSample& s, bool first) {
  FusionStrategy& f = *cur_.filter;
  ScopedStepTimer timer(timings_, "zupt");
  const bool flight_state = init_.haveFlightState();
  const ZuptMeasurement z = restMeasurement(s, cur_.rest_rate, options_.zupt, options_.imu.gyro_noise_density,
                                            cur_.noise_adapter.scale(), flight_state);
  const Linearization lin = sensors_.zupt.linearize(z, f.state());
  if (!f.update(lin, restGate(static_cast<int>(lin.residual.size()), options_.zupt, flight_state)).accepted)
    event(first, "gated_zupt");
  cur_.last_zupt = s.t;
  cur_.rest_rate.reset();
  if (first) ++instance_stats_[setup_.imu_id].n_updates;
}

}  // namespace meshnav::estimator
