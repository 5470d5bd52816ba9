/// @file estimator_node_gravity.cpp
/// @brief EstimatorNode: which way gravity points in the anchors' frame G (docs/robustness.md,
/// "Which way is up"). The scheduled check a full alignment window after the first
/// initialization, the early check when the range innovations say the model is far off before
/// that, and the re-initialization with gravity along +z of G.

#include <spdlog/spdlog.h>

#include "estimator/node/estimator_node.h"

namespace meshnav::estimator {

namespace {

std::string costsText(const MotionAligner::GravityCheck& c) {
  return fmt::format("cost {:.1f} with gravity along -z, {:.1f} along +z, margin {:.1f}, {} ranges", c.cost_z_up,
                     c.cost_z_down, c.margin, c.n_ranges);
}

}  // namespace

std::optional<MotionAligner::GravityCheck> EstimatorNode::runGravityCheck() {
  ScopedStepTimer timer(timings_, "align");  // the check alone: adoptGravityAlongPlusZ times its own solve
  return cur_.filter ? aligner_.checkGravityDirection(cur_.filter->state().imu.bias_gyro_rad_s)
                     : aligner_.checkGravityDirection(Eigen::Vector3d::Zero());
}

bool EstimatorNode::hasVerticalSensor() const {
  return last_pressure_pa_ || last_align_height_ ||
         (cur_.filter && (!cur_.filter->state().values<BaroBiasKind>().empty() ||
                          !cur_.filter->state().values<HeightBiasKind>().empty()));
}

void EstimatorNode::checkGravityDirection(Timestamp t) {
  gravity_check_at_.reset();
  ++gravity_checks_;
  const auto c = runGravityCheck();
  if (!c) {
    spdlog::info("estimator: gravity direction not checked at t={}: {}", formatSeconds(t), aligner_.reason());
    if (gravity_checks_ < kMaxGravityChecks) gravity_check_at_ = t + Duration::fromSec(options_.init.motion_window_s);
    return;
  }
  if (c->zDown()) {
    takeGravityAlongPlusZ(t, *c);
  } else {
    spdlog::info("estimator: gravity direction at t={}: {} ({})", formatSeconds(t),
                 c->zUp() ? "along -z of G as assumed" : "undecided", costsText(*c));
    // Undecided (little motion in the window): again a window later, at most kMaxGravityChecks times.
    if (!c->zUp() && gravity_checks_ < kMaxGravityChecks)
      gravity_check_at_ = t + Duration::fromSec(options_.init.motion_window_s);
  }
}

void EstimatorNode::noteRangeNisRatio(double ratio) {
  const double limit = options_.init.gravity_early_check_nis_ratio;
  if (limit > 0.0 && ratio >= limit && gravity_checks_ == 0 && gravity_check_at_ && !gravity_early_checked_)
    gravity_early_check_due_ = true;
}

void EstimatorNode::earlyGravityCheck(Timestamp t) {
  gravity_early_check_due_ = false;
  gravity_early_checked_ = true;
  // With baro or heights the frame is taken as it is (they measure along −z); the scheduled
  // check says so once.
  if (hasVerticalSensor()) return;
  diag_.count("gravity_early_check");
  const auto c = runGravityCheck();
  if (!c || !c->zDown()) {
    spdlog::info("estimator: early gravity check at t={} (median range NIS {:.1f}x its expected value): {}; the "
                 "check at t={} still runs",
                 formatSeconds(t), cur_.noise_adapter.lastRatio(),
                 !c ? aligner_.reason() : (c->zUp() ? "along -z of G as assumed" : "undecided") + (" (" + costsText(*c) + ")"),
                 formatSeconds(*gravity_check_at_));
    return;
  }
  gravity_check_at_.reset();
  ++gravity_checks_;
  takeGravityAlongPlusZ(t, *c);
}

void EstimatorNode::takeGravityAlongPlusZ(Timestamp t, const MotionAligner::GravityCheck& c) {
  diag_.count("anchor_frame_z_down");
  if (hasVerticalSensor()) {
    spdlog::warn(
        "estimator: at t={} the anchors' frame G fits the IMU upside down ({}), but baro or heights measure along "
        "-z: kept gravity along -z of G; expect poor estimates (docs/real_data.md)",
        formatSeconds(t), costsText(c));
    return;
  }
  spdlog::warn("estimator: at t={} the anchors' frame G fits the IMU upside down ({}): its z axis points down; "
               "gravity is taken along +z of G from now on (docs/real_data.md)",
               formatSeconds(t), costsText(c));
  gravity_z_sign_ = 1.0;
  aligner_.setGravityAlongPlusZ(true);
  zupt_model_ = ZuptModel(gravityG());
  gravity_flip_pending_ = true;
  adoptGravityAlongPlusZ(t);
}

void EstimatorNode::adoptGravityAlongPlusZ(Timestamp t) {
  last_flip_try_ = t;
  const auto r = solveAlignment(cur_.filter->state().imu.bias_gyro_rad_s);
  if (!r) {
    diag_.count("gravity_flip_refused");
    return;
  }
  gravity_flip_pending_ = false;
  replaceImu(r->imu, r->cov, r->t, r->last_imu);
  diag_.count("gravity_flip");
  spdlog::warn("estimator: re-initialized at t={} with gravity along +z of G from {} ranges (σ_p {:.2f} m, σ_yaw "
               "{:.1f} deg); anchors and bias states kept",
               formatSeconds(r->t), r->n_ranges, r->sigma_p_m, r->sigma_yaw_deg);
}

}  // namespace meshnav::estimator
