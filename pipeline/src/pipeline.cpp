#include "pipeline/pipeline.h"

namespace meshnav::pipeline {

Pipeline::Pipeline(const PipelineOptions& options, const SystemSetup& setup, PipelineSinks sinks)
    : options_(options), sinks_(std::move(sinks)) {
  estimator::EstimatorSinks es;
  es.pose = [this](const PoseEstimate& p) { queue_.emplace_back(p); };
  es.anchors = [this](const std::vector<AnchorEstimate>& a) { queue_.emplace_back(a); };
  es.status = [this](const EstimatorStatus& s) { queue_.emplace_back(s); };
  estimator_ = std::make_unique<estimator::EstimatorNode>(options_.estimator, setup, es);
  if (options_.calibration_enabled) {
    calib::CalibratorNodeOptions node_opts = options_.calibrator_node;
    if (!options_.mission) node_opts.auto_mode = true;
    calib::CalibratorSinks cs;
    cs.anchor_init = [this](const AnchorInit& a) { queue_.emplace_back(a); };
    cs.status = [this](const CalibStatus& s) { queue_.emplace_back(s); };
    calibrator_ = std::make_unique<calib::CalibratorNode>(options_.calibrator, setup, cs, node_opts);
  }
  if (options_.mission) {
    mission::MissionSinks ms;
    ms.calib_cmd = [this](const CalibCommand& c) { queue_.emplace_back(c); };
    ms.estimator_cmd = [this](const EstimatorCommand& c) { queue_.emplace_back(c); };
    ms.status = [this](const MissionStatus& s) { queue_.emplace_back(s); };
    mission_ = std::make_unique<mission::MissionNode>(*options_.mission, ms);
  }
}

Pipeline::~Pipeline() = default;

void Pipeline::onInput(const estimator::EstimatorInput& in) {
  const Timestamp t = estimator::inputTime(in);
  if (!t0_set_) {
    // Mission times are relative to the dataset's first sample.
    if (mission_) mission_->setT0(t);
    t0_set_ = true;
  }
  estimator_->onInput(in);
  if (calibrator_) {
    if (const auto* r = std::get_if<RangeSample>(&in)) calibrator_->onRange(*r);
    calibrator_->tick(t);
  }
  if (mission_) mission_->onTime(t);
  drain();
}

void Pipeline::drain() {
  while (!queue_.empty()) {
    Event ev = std::move(queue_.front());
    queue_.pop_front();
    std::visit(
        [this](auto& m) {
          using T = std::decay_t<decltype(m)>;
          if constexpr (std::is_same_v<T, PoseEstimate>) {
            if (calibrator_ && (options_.pose_to_calibrator_hz <= 0.0 || !last_pose_to_calibrator_ ||
                                (m.t - *last_pose_to_calibrator_).sec() >= 1.0 / options_.pose_to_calibrator_hz)) {
              calibrator_->onPose(m);
              last_pose_to_calibrator_ = m.t;
            }
            if (sinks_.pose) sinks_.pose(m);
          } else if constexpr (std::is_same_v<T, std::vector<AnchorEstimate>>) {
            if (calibrator_) calibrator_->onAnchors(m);
            if (sinks_.anchors) sinks_.anchors(m);
          } else if constexpr (std::is_same_v<T, EstimatorStatus>) {
            if (mission_) mission_->onEstimatorStatus(m);
            if (sinks_.estimator_status) sinks_.estimator_status(m);
          } else if constexpr (std::is_same_v<T, AnchorInit>) {
            anchor_inits_.push_back(m);
            estimator_->onAnchorInit(m);
            if (sinks_.anchor_init) sinks_.anchor_init(m);
          } else if constexpr (std::is_same_v<T, CalibStatus>) {
            if (mission_) mission_->onCalibStatus(m);
            if (sinks_.calib_status) sinks_.calib_status(m);
          } else if constexpr (std::is_same_v<T, CalibCommand>) {
            if (calibrator_) calibrator_->onCommand(m);
          } else if constexpr (std::is_same_v<T, EstimatorCommand>) {
            estimator_->onCommand(m);
          } else if constexpr (std::is_same_v<T, MissionStatus>) {
            if (sinks_.mission_status) sinks_.mission_status(m);
          }
        },
        ev);
  }
}

}  // namespace meshnav::pipeline
