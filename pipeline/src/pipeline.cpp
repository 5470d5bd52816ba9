#include "pipeline/pipeline.h"

#include <stdexcept>

#include "common/skew.h"
#include "pipeline/fleet_calibrator_feed.h"

namespace meshnav::pipeline {

Pipeline::Pipeline(const PipelineOptions& options, const SystemSetup& setup, PipelineSinks sinks)
    : Pipeline(options, std::vector<Vehicle>{Vehicle{"", setup}}, setup, std::move(sinks)) {}

Pipeline::Pipeline(const PipelineOptions& options, std::vector<Vehicle> vehicles, const SystemSetup& fleet_setup,
                   PipelineSinks sinks)
    : options_(options), sinks_(std::move(sinks)), vehicles_(std::move(vehicles)), fleet_setup_(fleet_setup) {
  if (vehicles_.empty()) throw std::invalid_argument("pipeline: no vehicle");
  feed_ = std::make_unique<FleetCalibratorFeed>(vehicles_, fleet_setup, diag_);
  for (size_t v = 0; v < vehicles_.size(); ++v) {
    estimator::EstimatorSinks es;
    es.pose = [this, v](const PoseEstimate& p) { queue_.push_back({v, p}); };
    if (sinks_.pose_smoothed || (options_.calibration_enabled && options_.calibrator_on_smoothed))
      es.pose_smoothed = [this, v](const PoseEstimate& p) { queue_.push_back({v, SmoothedPose{p}}); };
    es.anchors = [this, v](const std::vector<AnchorEstimate>& a) { queue_.push_back({v, a}); };
    es.status = [this, v](const EstimatorStatus& s) { queue_.push_back({v, s}); };
    estimators_.push_back(std::make_unique<estimator::EstimatorNode>(options_.estimator, vehicles_[v].setup, es));
  }
  if (vehicles_.size() > 1) router_ = std::make_unique<PeerRangeRouter>(options_.peer_routing, vehicles_.size());
  last_pose_to_calibrator_.resize(vehicles_.size());
  awaiting_smoothed_.resize(vehicles_.size());
  if (options_.calibration_enabled) {
    calib::CalibratorNodeOptions node_opts = options_.calibrator_node;
    if (!options_.mission) node_opts.auto_mode = true;
    calib::CalibratorSinks cs;
    cs.anchor_init = [this](const AnchorInit& a) { queue_.push_back({0, a}); };
    cs.status = [this](const CalibStatus& s) { queue_.push_back({0, s}); };
    calibrator_ = std::make_unique<calib::CalibratorNode>(options_.calibrator, fleet_setup, cs, node_opts,
                                                          feed_->vehicleOfTag());
  }
  if (options_.mission) {
    mission::MissionSinks ms;
    ms.calib_cmd = [this](const CalibCommand& c) { queue_.push_back({0, c}); };
    ms.estimator_cmd = [this](const EstimatorCommand& c) { queue_.push_back({0, c}); };
    ms.status = [this](const MissionStatus& s) { queue_.push_back({0, s}); };
    mission_ = std::make_unique<mission::MissionNode>(*options_.mission, ms);
  }
}

Pipeline::~Pipeline() = default;

void Pipeline::onInput(size_t vehicle, const estimator::EstimatorInput& in) {
  estimator::EstimatorNode& node = *estimators_.at(vehicle);
  const Timestamp t = estimator::inputTime(in);
  if (!t0_set_) {
    // Mission times are relative to the dataset's (the fleet's) first sample.
    if (mission_) mission_->setT0(t);
    t0_set_ = true;
  }
  if (vehicles_.size() > 1)
    if (const auto* r = std::get_if<RangeSample>(&in)) {
      const SystemSetup& mine = vehicles_[vehicle].setup;
      const auto foreign = [&](SensorId id) { return fleet_setup_.isTag(id) && !mine.isTag(id); };
      if (foreign(r->id_initiator) || foreign(r->id_responder)) {
        // A range to another vehicle's tag (the calibrator needs it not).
        diag_.count("inter_vehicle_range:" + vehicles_[vehicle].name);
        if (!options_.inter_vehicle_ranges) return;
        routeInterVehicleRange(vehicle, *r);
        drain();  // the receiver's outputs
        return;
      }
      // A range of this vehicle's tag to an anchor it can use (known or calibrated): its anchor count.
      const SensorId other = mine.isTag(r->id_initiator) ? r->id_responder : r->id_initiator;
      if ((mine.isTag(r->id_initiator) || mine.isTag(r->id_responder)) &&
          (fleet_setup_.isKnownAnchor(other) || calibrated_anchors_.count(other)))
        router_->noteAnchorRange(vehicle, other, r->t);
    }
  node.onInput(in);
  if (calibrator_) {
    if (const auto* r = std::get_if<RangeSample>(&in); r && feed_->forCalibrator(*r)) calibrator_->onRange(*r);
    calibrator_->tick(t);
  }
  if (mission_) mission_->onTime(t);
  drain();
}

void Pipeline::routeInterVehicleRange(size_t vehicle, const RangeSample& r) {
  // Each range once: the same exchange may be logged by both vehicles (as the anchors' mesh is).
  constexpr int64_t kKeepUs = 10'000'000;
  while (!peer_ranges_.empty() && std::get<0>(*peer_ranges_.begin()) < r.t.us - kKeepUs)
    peer_ranges_.erase(peer_ranges_.begin());
  const auto key = pairKey(r.id_initiator, r.id_responder);
  if (!peer_ranges_.emplace(r.t.us, key.first, key.second).second) {
    diag_.count("inter_vehicle_range_duplicate");
    return;
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
    return;
  }
  if (options_.peer_truth) {
    // The oracle: both vehicles, each with the other's true tag (independent of either estimate).
    for (const auto& [receiver, sender, peer_tag] :
         {std::tuple{*va, *vb, r.id_responder}, std::tuple{*vb, *va, r.id_initiator}}) {
      const std::optional<PoseSample> truth = options_.peer_truth(sender, r.t);
      if (!truth || !estimators_[receiver]->pose()) continue;
      PeerRange pr;
      pr.t = r.t;
      pr.range = r;
      pr.peer_tag = peer_tag;
      pr.p_peer_tag_in_G = truth->p_IinG + truth->q_ItoG * vehicles_[sender].setup.rel_tag_positions.at(peer_tag);
      pr.cov_peer_tag_m2.setZero();
      diag_.count("inter_vehicle_range_to:" + vehicles_[receiver].name);
      estimators_[receiver]->onInput(pr);
    }
    return;
  }
  const std::optional<PoseEstimate> pa = estimators_[*va]->pose(), pb = estimators_[*vb]->pose();
  // One of the two learns from the range, with the other's estimate as its anchor (never both:
  // each would count the other's information as independent of its own), and only where that
  // estimate holds nothing of the receiver's (PeerRangeRouter: from a vehicle with anchors to one
  // without, docs/decisions/016-fleet-sharing.md).
  PeerSide sa, sb;
  sa.has_estimate = pa.has_value();
  sb.has_estimate = pb.has_value();
  if (pa) sa.cov_p_trace_m2 = pa->cov_p_m2.trace();
  if (pb) sb.cov_p_trace_m2 = pb->cov_p_m2.trace();
  const PeerRangeRouter::Decision decision = router_->decide(*va, sa, *vb, sb, r.t);
  if (!decision.receiver) {
    diag_.count("inter_vehicle_range_" + decision.why);
    return;
  }
  const bool to_a = *decision.receiver == *va;
  const size_t receiver = to_a ? *va : *vb, sender = to_a ? *vb : *va;
  const PoseEstimate& ps = to_a ? *pb : *pa;
  const SensorId peer_tag = to_a ? r.id_responder : r.id_initiator;
  // The sender's tag at the range's time, from its pose (at most one input older): p_S = p_I +
  // v dt + R l, with δθ local (R = R̂ Exp(δθ)): ∂p_S/∂δθ = −R̂ [l]×; Σ_S = Σ_p + dt² Σ_v + J Σ_θ Jᵀ.
  const Eigen::Vector3d& l = vehicles_[sender].setup.rel_tag_positions.at(peer_tag);
  const double dt = (r.t - ps.t).sec();
  const Eigen::Matrix3d R = ps.q_ItoG.toRotationMatrix();
  const Eigen::Matrix3d J = -R * skew(l);
  PeerRange pr;
  pr.t = r.t;
  pr.range = r;
  pr.peer_tag = peer_tag;
  pr.p_peer_tag_in_G = ps.p_IinG + dt * ps.v_IinG + R * l;
  pr.cov_peer_tag_m2 = ps.cov_p_m2 + dt * dt * ps.cov_v + J * ps.cov_theta_rad2 * J.transpose();
  diag_.count("inter_vehicle_range_to:" + vehicles_[receiver].name);
  router_->noteReceived(receiver, sender, r.t);
  estimators_[receiver]->onInput(pr);
}

void Pipeline::finish() {
  for (auto& e : estimators_) {
    e->flushHeld();
    e->finishRerun();
    e->flushSmoothed();
  }
  drain();
}

void Pipeline::drain() {
  while (!queue_.empty()) {
    Event ev = std::move(queue_.front());
    queue_.pop_front();
    const size_t v = ev.vehicle;
    std::visit(
        [this, v](auto& m) {
          using T = std::decay_t<decltype(m)>;
          if constexpr (std::is_same_v<T, PoseEstimate>) {
            auto& last = last_pose_to_calibrator_[v];
            if (calibrator_ &&
                (options_.pose_to_calibrator_hz <= 0.0 || !last || (m.t - *last).sec() >= 1.0 / options_.pose_to_calibrator_hz)) {
              calibrator_->onPose(m, v);
              last = m.t;
              if (options_.calibrator_on_smoothed) awaiting_smoothed_[v].insert(m.t.us);
            }
            if (sinks_.pose) sinks_.pose(v, m);
          } else if constexpr (std::is_same_v<T, SmoothedPose>) {
            // The calibrator's pose at this instant becomes the smoothed one (same instant: the
            // newer replaces it, CalibratorNode::onPose).
            auto& awaiting = awaiting_smoothed_[v];
            if (auto it = awaiting.find(m.pose.t.us); it != awaiting.end()) {
              calibrator_->onPose(m.pose, v);
              awaiting.erase(awaiting.begin(), std::next(it));
            }
            if (sinks_.pose_smoothed) sinks_.pose_smoothed(v, m.pose);
          } else if constexpr (std::is_same_v<T, std::vector<AnchorEstimate>>) {
            if (calibrator_) calibrator_->onAnchors(feed_->anchorsFrom(v, m));
            if (sinks_.anchors) sinks_.anchors(v, m);
          } else if constexpr (std::is_same_v<T, EstimatorStatus>) {
            if (mission_ && v == 0) mission_->onEstimatorStatus(m);
            if (sinks_.estimator_status) sinks_.estimator_status(v, m);
          } else if constexpr (std::is_same_v<T, AnchorInit>) {
            anchor_inits_.push_back(m);
            calibrated_anchors_.insert(m.id);
            for (size_t i = 0; i < estimators_.size(); ++i)
              estimators_[i]->onAnchorInit(feed_->forVehicle(i, m));
            if (sinks_.anchor_init) sinks_.anchor_init(m);
          } else if constexpr (std::is_same_v<T, CalibStatus>) {
            if (mission_) mission_->onCalibStatus(m);
            if (sinks_.calib_status) sinks_.calib_status(m);
          } else if constexpr (std::is_same_v<T, CalibCommand>) {
            if (calibrator_) calibrator_->onCommand(m);
          } else if constexpr (std::is_same_v<T, EstimatorCommand>) {
            for (auto& e : estimators_) e->onCommand(m);
          } else if constexpr (std::is_same_v<T, MissionStatus>) {
            if (sinks_.mission_status) sinks_.mission_status(m);
          }
        },
        ev.msg);
  }
}

}  // namespace meshnav::pipeline
