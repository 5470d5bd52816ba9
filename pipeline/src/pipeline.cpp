#include "pipeline/pipeline.h"

#include <stdexcept>

#include "common/log_context.h"
#include "pipeline/fleet_calibrator_feed.h"
#include "pipeline/peer_range_feed.h"

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
  if (vehicles_.size() > 1) peers_ = std::make_unique<PeerRangeFeed>(vehicles_, fleet_setup, options_.peer_routing, diag_);
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
  if (peers_)
    if (const auto* r = std::get_if<RangeSample>(&in); r && peers_->interVehicle(vehicle, *r)) {
      // A range to another vehicle's tag (the calibrator needs it not).
      if (!options_.inter_vehicle_ranges) return;
      routeInterVehicleRange(*r);
      drain();  // the receiver's outputs
      return;
    }
  {
    const LogContext::Scope scope(vehicleLogName(vehicle));
    node.onInput(in);
  }
  if (calibrator_) {
    if (const auto* r = std::get_if<RangeSample>(&in); r && feed_->forCalibrator(*r)) calibrator_->onRange(*r);
    calibrator_->tick(t);
  }
  if (mission_) mission_->onTime(t);
  drain();
}

void Pipeline::routeInterVehicleRange(const RangeSample& r) {
  const std::optional<PeerRangeFeed::Ends> ends = peers_->admit(r);
  if (!ends) return;
  if (options_.peer_truth) {
    // The oracle: both vehicles, each with the other's true tag (independent of either estimate).
    for (const auto& [receiver, sender, peer_tag] :
         {std::tuple{ends->a, ends->b, r.id_responder}, std::tuple{ends->b, ends->a, r.id_initiator}}) {
      const std::optional<PoseSample> truth = options_.peer_truth(sender, r.t);
      if (!truth || !estimators_[receiver]->pose()) continue;
      PeerRange pr;
      pr.t = r.t;
      pr.range = r;
      pr.peer_tag = peer_tag;
      pr.p_peer_tag_in_G = truth->p_IinG + truth->q_ItoG * peers_->leverArm(sender, peer_tag);
      pr.cov_peer_tag_m2.setZero();
      diag_.count("inter_vehicle_range_to:" + vehicles_[receiver].name);
      const LogContext::Scope scope(vehicleLogName(receiver));
      estimators_[receiver]->onInput(pr);
    }
    return;
  }
  // The sender's pose: its estimator's now, at most one input older than the range.
  if (auto routed = peers_->route(r, *ends, estimators_[ends->a]->pose(), estimators_[ends->b]->pose())) {
    const LogContext::Scope scope(vehicleLogName(routed->receiver));
    estimators_[routed->receiver]->onInput(routed->range);
  }
}

const std::string* Pipeline::vehicleLogName(size_t v) const {
  return estimators_.size() > 1 ? &vehicles_.at(v).name : nullptr;  // one vehicle: its log says enough
}

void Pipeline::finish() {
  for (size_t v = 0; v < estimators_.size(); ++v) {
    const LogContext::Scope scope(vehicleLogName(v));
    estimators_[v]->flushHeld();
    estimators_[v]->finishRerun();
    estimators_[v]->flushSmoothed();
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
            if (peers_) peers_->onAnchorInit(m.id);
            for (size_t i = 0; i < estimators_.size(); ++i) {
              const LogContext::Scope scope(vehicleLogName(i));
              estimators_[i]->onAnchorInit(feed_->forVehicle(i, m));
            }
            if (sinks_.anchor_init) sinks_.anchor_init(m);
          } else if constexpr (std::is_same_v<T, CalibStatus>) {
            if (mission_) mission_->onCalibStatus(m);
            if (sinks_.calib_status) sinks_.calib_status(m);
          } else if constexpr (std::is_same_v<T, CalibCommand>) {
            if (calibrator_) calibrator_->onCommand(m);
          } else if constexpr (std::is_same_v<T, EstimatorCommand>) {
            for (size_t i = 0; i < estimators_.size(); ++i) {
              const LogContext::Scope scope(vehicleLogName(i));
              estimators_[i]->onCommand(m);
            }
          } else if constexpr (std::is_same_v<T, MissionStatus>) {
            if (sinks_.mission_status) sinks_.mission_status(m);
          }
        },
        ev.msg);
  }
}

}  // namespace meshnav::pipeline
