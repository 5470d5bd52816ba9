/// @file estimator_node_robustness.cpp
/// @brief EstimatorNode, second part: initialization (landed and in motion), the alignment window
/// and stillness fed in arrival order, IMU gaps, health and recovery (docs/robustness.md). The
/// first part, estimator_node.cpp, holds input handling, processing and outputs.

#include <spdlog/spdlog.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <stdexcept>

#include "common/atmosphere.h"
#include "estimator/core/so3.h"
#include "estimator/filter/strategy_factory.h"
#include "estimator/init/initial_states.h"
#include "estimator/node/estimator_node.h"
#include "estimator/node/node_internals.h"

namespace meshnav::estimator {

namespace {
/// Added to a lost filter's heading variance before it judges rival poses: a floor of (1°)², twice
/// the aligner's own attitude floor of 0.5° per axis, for a filter that was lost [rad²].
constexpr double kHeadingPriorFloorRad2 = (1.0 * M_PI / 180.0) * (1.0 * M_PI / 180.0);
}  // namespace

using node_internal::weakestPositionAxis;

void EstimatorNode::feedInitializer(const EstimatorInput& in) {
  // Anchors that come before the pose are held and applied at the initialization.
  if (const auto* a = std::get_if<AnchorInit>(&in)) sensors_.anchor_join.hold(*a);
  if (const auto* c = std::get_if<EstimatorCommand>(&in); c && c->action == EstimatorCommand::Action::AddAnchor)
    sensors_.anchor_join.hold(c->anchorToAdd());
  if (auto belief = init_.tryInitialize(in, cur_.landed)) initialize(*belief);
}

void EstimatorNode::logInitialization(const InitialBelief& b) const {
  const double yaw_deg = so3::yawOf(b.imu.q_ItoG) * 180.0 / M_PI;
  const double sigma_yaw_deg =
      std::sqrt(so3::yawVariance(b.imu.q_ItoG, b.cov.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta))) * 180.0 / M_PI;
  spdlog::info(
      "estimator: initialized at t={} from {} p_IinG=[{:.3f}, {:.3f}, {:.3f}] m, yaw {:.1f} deg (σ_p {:.2f} m, "
      "σ_yaw {:.1f} deg){}",
      formatSeconds(b.t), b.from_ranges ? "ranges" : (b.from_checkpoint ? "a checkpoint" : "initial_pose"), b.imu.p_IinG.x(), b.imu.p_IinG.y(),
      b.imu.p_IinG.z(), yaw_deg, weakestPositionAxis(b.cov.block<3, 3>(ImuErr::kP, ImuErr::kP)).first,
      sigma_yaw_deg,
      b.from_ranges ? fmt::format(", {} ranges, rms {:.3f} m", b.n_ranges_used, b.range_fit_rms_m) : "");
  if (b.height_bias)
    spdlog::info("estimator: the alignment used {} heights: rangefinder bias {:.3f} m (σ {:.3f} m)", b.n_heights_used,
                 b.height_bias->first, std::sqrt(b.height_bias->second));
  if (!sensors_.baro.reference() && sensors_.baro.enabled())
    spdlog::warn("estimator: no baro reference pressure (none in setup, no landed baro data): baro unused");
}

void EstimatorNode::initialize(const InitialBelief& b) {
  const double sign_before = gravity_.zSign();
  gravity_.onInitialized(b.t, b.gravity_z_sign);
  if (gravity_.zSign() != sign_before) sensors_.zupt = ZuptModel(gravityG());  // the aligner has turned already
  auto filter = makeStrategy(options_, gravity_.zSign());
  filter->reset(setup_.imu_id, b.imu, b.cov, b.t);
  if (options_.baro.enabled && b.baro_reference_pa) {
    sensors_.baro.setReference(b.baro_reference_pa);
    filter->addInstance<BaroBiasKind>(setup_.baro_id, b.baro_bias_m, Eigen::MatrixXd::Constant(1, 1, b.baro_bias_var_m2));
  } else if (options_.baro.enabled && resume_.keptBaroReference()) {
    sensors_.baro.setReference(resume_.keptBaroReference());  // a restart in flight: the predecessor's
  }                                                        // reference (its bias: a kept instance)
  sensors_.height.setBiasPrior(b.height_bias);  // the height instance is added at the first usable height
  addSetupAnchorStates(*filter, setup_, options_.uwb);
  addTagBiasStates(*filter, setup_, options_.uwb);
  setUwbClockPrior(*filter);
  resume_.restoreKept(*filter, b.t, sensors_.baro.reference());  // replace the priors
  cur_.filter = std::move(filter);
  cur_.mean_reading.reset();
  cur_.last_imu = b.last_imu;
  cur_.prev_imu.reset();
  cur_.landed = b.landed;
  cur_.last_zupt = b.t;
  cur_.rest_rate.reset();
  onReinitialized(b.t);
  timeline_.advance(b.t);
  logInitialization(b);
  applyHeldAnchors(b.t);
}

std::optional<std::pair<Timestamp, double>> EstimatorNode::unconfirmedRecovery() const {
  const auto t = recovery_confirmation_.pending();
  if (!t || !initialized()) return std::nullopt;
  return std::make_pair(*t, recovery_confirmation_.okFor(cur_.filter->state().t));
}

std::string EstimatorNode::waitingFor() const {
  if (!imu_units_.fault().empty()) return "IMU: " + imu_units_.fault();
  if (initialized()) return "";
  return init_.waitingFor();
}

void EstimatorNode::updateHealth(Timestamp t) {
  if (!initialized()) return;
  if (reentry_.holding()) return;  // ranges are arriving, held for their joint check (at most uwb.reentry_hold_s)
  checkFlightVolume(t);  // after every input: a slide across the plane takes a few tenths of a second
  if (!recovery_.evaluationDue(t)) return;
  const auto [sigma_p, axis] = weakestPositionAxis(cur_.filter->covariance(setup_.imu_id, setup_.imu_id)
                                                       .block<3, 3>(ImuErr::kP, ImuErr::kP));
  if (health_.evaluate(t, sigma_p)) {
    diag_.count(std::string("health_") + healthName(health_.health()));
    const std::string msg = fmt::format("estimator: health {} at t={}{}{}", healthName(health_.health()),
                                        formatSeconds(t), health_.reason().empty() ? "" : ": ", health_.reason());
    if (health_.health() == Health::Ok)
      spdlog::info("{}", msg);
    else
      spdlog::warn("{}", msg);
  }
  const Health h = health_.health();
  if (recovery_confirmation_.noteHealth(t, h)) {
    diag_.count("recovery_confirmed");
    spdlog::info("estimator: the recovery is confirmed at t={}: {} ranges fitted since (mean NIS {:.2f})",
                 formatSeconds(t), recovery_confirmation_.rangesFitted(), recovery_confirmation_.meanNis());
  }
  // Degraded by gating alone, with the accepted ranges fitting, is what NLOS outliers look like:
  // a re-alignment from those ranges is then more likely wrong than the filter (RecoveryPolicy).
  if (recovery_.alignmentDue(t, h, h == Health::Degraded && health_.acceptedRangesFit(t))) tryRecover(t);
}

void EstimatorNode::tryRecover(Timestamp t) {
  const bool lost = health_.health() == Health::Lost;
  // Lost after a range outage, the position has drifted but the gyro kept the heading: rival poses
  // that fit the ranges alike are told apart by it (MotionAligner::solve; docs/robustness.md).
  std::optional<MotionAligner::HeadingPrior> heading;
  if (lost) {
    const ImuState& x = cur_.filter->state().imu;
    const Eigen::Matrix3d P_tt =
        cur_.filter->covariance(setup_.imu_id, setup_.imu_id).block<3, 3>(ImuErr::kTheta, ImuErr::kTheta);
    heading = MotionAligner::HeadingPrior{so3::yawOf(x.q_ItoG), so3::yawVariance(x.q_ItoG, P_tt) + kHeadingPriorFloorRad2};
  }
  const int decided = init_.aligner().headingDecisions(), contradicted = init_.aligner().headingPriorRejections();
  const auto r = init_.align(cur_.filter->state().imu.bias_gyro_rad_s, heading);
  if (r && init_.aligner().headingDecisions() != decided) diag_.count("recovery_heading_prior_decided");
  if (init_.aligner().headingPriorRejections() != contradicted) diag_.count("recovery_heading_prior_contradicted");
  if (!r) {
    if (!lost) return;  // degraded: nothing to compare with
    diag_.count("recovery_refused");
    spdlog::warn("estimator: lost at t={}, cannot re-initialize yet: {}", formatSeconds(t), init_.alignerReason());
    return;
  }
  // Degraded: replace only a filter that the aligned pose contradicts (a runaway not yet gated out).
  if (!lost) {
    const double chi2 = RecoveryPolicy::disagreement(cur_.filter->state().imu,
                                                     cur_.filter->covariance(setup_.imu_id, setup_.imu_id), *r);
    if (!recovery_.contradicts(chi2)) return;
    const bool after_gap = recovery_.afterGap(t);
    diag_.count(after_gap ? "recovery_after_imu_gap" : "recovery_degraded");
    spdlog::warn("estimator: {} at t={} and the aligned pose disagrees (chi2 {:.1f} > {:.1f})",
                 after_gap ? "after an IMU gap" : "degraded", formatSeconds(t), chi2, recovery_.bound());
  }
  const ImuState before = cur_.filter->state().imu;
  replaceImu(r->imu, r->cov, r->t, r->last_imu);
  recovery_confirmation_.noteRecovery(t);
  diag_.count("recovery");
  spdlog::warn("estimator: recovered at t={}: re-initialized from {} ranges and the IMU (moved {:.2f} m, "
               "σ_p {:.2f} m, σ_yaw {:.1f} deg); anchors and bias states kept",
               formatSeconds(r->t), r->n_ranges, (r->imu.p_IinG - before.p_IinG).norm(), r->sigma_p_m,
               r->sigma_yaw_deg);
}

void EstimatorNode::checkFlightVolume(Timestamp t) {
  if (!volume_.active() || !cur_.last_imu) return;
  FusionStrategy& f = *cur_.filter;
  const ImuState& x = f.state().imu;
  if (volume_.isMirrorImage(x.p_IinG)) {
    const auto m = volume_.mirrorImage(t, x, f.covariance(setup_.imu_id, setup_.imu_id));
    replaceImu(m->x, m->P, f.state().t, *cur_.last_imu);
    return;
  }
  if (!volume_.sideConstraintDue(t)) return;
  const Eigen::Matrix3d P_pp = f.covariance(setup_.imu_id, setup_.imu_id).block<3, 3>(ImuErr::kP, ImuErr::kP);
  if (const auto lin = volume_.sideConstraint(t, setup_.imu_id, x.p_IinG, P_pp))
    f.update(*lin, 0.0);  // not gated: a constraint, not a sensor
}

void EstimatorNode::replaceImu(const ImuState& x, const ImuMatrix& P, Timestamp t, const ImuSample& last_imu) {
  flushSmoothed();  // the chain of IMU beliefs ends here: the smoothed poses before it go out now
  cur_.replaceImu(x, P, t, last_imu, options_, setup_.imu_id, gravity_.zSign());
  setUwbClockPrior(*cur_.filter);
  reentry_.restart(t);  // held ranges were in the history; the new pose comes from ranges
  onReinitialized(t);
}

void EstimatorNode::setUwbClockPrior(FusionStrategy& f) const {
  const double sigma_s = ClockOffsetKind::priorSigma(setup_, options_);
  if (!(sigma_s > 0.0) || !sensors_.range.enabled()) return;
  const std::vector<SensorId> joint_set = f.jointSetOf(setup_.uwb_clock_id);  // DAH: stays in its set
  f.removeInstance(setup_.uwb_clock_id);
  f.addInstance<ClockOffsetKind>(setup_.uwb_clock_id, setup_.uwb_clock.offset_s,
                                 Eigen::MatrixXd::Constant(1, 1, sigma_s * sigma_s));
  if (!joint_set.empty()) f.joinJointSet(joint_set);
}

void EstimatorNode::onReinitialized(Timestamp t) {
  rerun_.abandon();  // a re-run may not restore the state before it (it starts from the new pose next time)
  timeline_.restart(t);  // nor may a rewind
  health_.reset(t);
}

void EstimatorNode::injectPoseError(const Eigen::Vector3d& dp_m, double dyaw_rad) {
  if (!initialized()) return;
  ImuState x = cur_.filter->state().imu;
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(dyaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  x.p_IinG += dp_m;
  x.v_IinG = Rz * x.v_IinG;
  x.q_ItoG = Eigen::Quaterniond(Rz * x.q_ItoG.toRotationMatrix()).normalized();
  const ImuMatrix P = cur_.filter->covariance(setup_.imu_id, setup_.imu_id);
  const ImuSample last = cur_.last_imu ? *cur_.last_imu : ImuSample{};
  const Timestamp t = cur_.filter->state().t;
  const auto keep_health = health_;
  replaceImu(x, P, t, last);
  health_ = keep_health;  // the fault is not a re-initialization
  diag_.count("injected_pose_error");
}

}  // namespace meshnav::estimator
