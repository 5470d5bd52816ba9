/// @file estimator_node_gravity.cpp
/// @brief EstimatorNode as the context of GravityDirection (estimator/init/gravity_direction.h):
/// the aligner's comparison of both gravity signs, the vertical sensors, and the re-initialization
/// with gravity along +z of G.

#include <spdlog/spdlog.h>

#include "estimator/node/estimator_node.h"

namespace meshnav::estimator {

struct EstimatorNode::GravityAdapter final : GravityDirection::Context {
  explicit GravityAdapter(EstimatorNode& node) : n(node) {}
  std::optional<MotionAligner::GravityCheck> compareGravitySigns() override {
    ScopedStepTimer timer(n.timings_, "align");  // the check alone: a re-initialization times its own solve
    return n.init_.aligner().checkGravityDirection(n.cur_.filter ? n.cur_.filter->state().imu.bias_gyro_rad_s
                                                                 : Eigen::Vector3d::Zero());
  }
  std::string whyNot() const override { return n.init_.alignerReason(); }
  bool hasVerticalSensor() const override { return n.hasVerticalSensor(); }
  void gravityTurned() override {
    n.init_.aligner().setGravityAlongPlusZ(true);
    n.sensors_.zupt = ZuptModel(n.gravityG());
  }
  bool reinitializeWithGravity(Timestamp t) override { return n.reinitializeWithPlusZ(t); }
  double rangeNisRatio() const override { return n.cur_.noise_adapter.lastRatio(); }
  EstimatorNode& n;
};

void EstimatorNode::runGravityDirection(Timestamp t) {
  GravityAdapter context(*this);
  gravity_.onImu(t, context);
}

bool EstimatorNode::hasVerticalSensor() const {
  return init_.sawVerticalSensor() ||
         (cur_.filter && (!cur_.filter->state().values<BaroBiasKind>().empty() ||
                          !cur_.filter->state().values<HeightBiasKind>().empty()));
}

bool EstimatorNode::reinitializeWithPlusZ(Timestamp t) {
  const auto r = init_.align(cur_.filter->state().imu.bias_gyro_rad_s);
  if (!r) return false;
  replaceImu(r->imu, r->cov, r->t, r->last_imu);
  spdlog::warn("estimator: re-initialized at t={} with gravity along +z of G from {} ranges (σ_p {:.2f} m, σ_yaw "
               "{:.1f} deg); anchors and bias states kept",
               formatSeconds(r->t), r->n_ranges, r->sigma_p_m, r->sigma_yaw_deg);
  return true;
}

}  // namespace meshnav::estimator
