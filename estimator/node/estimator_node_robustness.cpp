/// @file estimator_node_robustness.cpp
/// @brief EstimatorNode, second part: initialization (landed and in motion), the alignment window
/// and stillness fed in arrival order, IMU gaps, health and recovery (docs/robustness.md). The
/// first part, estimator_node.cpp, holds input handling, processing and outputs.

#include <spdlog/spdlog.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <stdexcept>

#include "common/atmosphere.h"
#include "estimator/filter/strategy_factory.h"
#include "estimator/node/estimator_node.h"
#include "estimator/node/node_internals.h"

namespace meshnav::estimator {

using node_internal::weakestPositionAxis;
using node_internal::whiteImuNoise;

void EstimatorNode::feedInitializer(const EstimatorInput& in) {
  std::visit(
      [&](const auto& m) {
        using T = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<T, ImuSample>) initializer_->addImu(m);
        if constexpr (std::is_same_v<T, BaroSample>) initializer_->addBaro(m);
        if constexpr (std::is_same_v<T, RangeSample>) initializer_->addRange(m);
        if constexpr (std::is_same_v<T, FlightStateSample>) initializer_->addFlightState(m);
        if constexpr (std::is_same_v<T, AnchorInit>) pending_anchor_inits_.push_back(m);
        if constexpr (std::is_same_v<T, EstimatorCommand>)
          if (m.action == EstimatorCommand::Action::AddAnchor) pending_anchor_inits_.push_back(m.anchorToAdd());
      },
      in);
  if (!std::holds_alternative<ImuSample>(in)) return;
  if (auto belief = initializer_->tryInitialize()) {
    initialize(*belief);
    return;
  }
  // At rest the landed data decides; in motion (or when it cannot fix the pose) the aligner.
  if (!initializer_->isStatic() || initializer_->waitingFor().rfind("motion", 0) == 0) tryMotionInitialization(inputTime(in));
}

/// Known-but-uncertain setup anchors (abs_anchor_sigmas) as estimated anchor instances.
void EstimatorNode::addSetupAnchorStates(FusionStrategy& f) const {
  for (const auto& [id, p] : setup_.abs_anchor_positions) {
    auto sig = setup_.abs_anchor_sigmas_m.find(id);
    if (sig == setup_.abs_anchor_sigmas_m.end()) continue;
    // Known-but-uncertain: its a-priori γ towards exactly known anchors and towards uncertain
    // anchors of smaller id (one owner per pair) become states too (independent a priori).
    BiasState biases;
    std::vector<double> gamma, var = {1.0, 1.0, 1.0};
    if (options_.uwb.estimate_setup_anchor_biases) {
      for (const auto& [peer, q] : setup_.abs_anchor_positions) {
        if (peer == id || (setup_.abs_anchor_sigmas_m.count(peer) && peer > id)) continue;
        const auto pb = setup_.findPairBias(id, peer);
        if (!pb || pb->sigma_gamma_m <= 0.0) continue;
        biases.peers.push_back(peer);
        gamma.push_back(pb->gamma_m);
        var.push_back(pb->sigma_gamma_m * pb->sigma_gamma_m);
      }
    }
    biases.gamma_m = Eigen::Map<const Eigen::VectorXd>(gamma.data(), static_cast<Eigen::Index>(gamma.size()));
    Eigen::VectorXd v = Eigen::Map<const Eigen::VectorXd>(var.data(), static_cast<Eigen::Index>(var.size()));
    v.head<3>() *= sig->second * sig->second;
    f.addInstance<AnchorKind>(id, AnchorState{p, biases}, v.asDiagonal().toDenseMatrix());
  }
}

void EstimatorNode::addTagBiasStates(FusionStrategy& f) const {
  if (options_.uwb.estimate_tag_biases) {
    // Tag instances with state: γ towards the setup's anchors (exact or known-but-uncertain) whose
    // a-priori bias is uncertain. Constant per pair, so a state rather than white noise.
    for (const auto& [tag, lever] : setup_.rel_tag_positions) {
      std::vector<SensorId> peers;
      std::vector<double> gamma, var;
      for (const auto& [anchor, p] : setup_.abs_anchor_positions) {
        const auto pb = setup_.findPairBias(tag, anchor);
        if (!pb || pb->sigma_gamma_m <= 0.0) continue;
        peers.push_back(anchor);
        gamma.push_back(pb->gamma_m);
        var.push_back(pb->sigma_gamma_m * pb->sigma_gamma_m);
      }
      if (!peers.empty())
        f.addInstance<TagBiasKind>(
            tag, BiasState{peers, Eigen::Map<Eigen::VectorXd>(gamma.data(), static_cast<long>(gamma.size()))},
            Eigen::Map<Eigen::VectorXd>(var.data(), static_cast<long>(var.size())).asDiagonal().toDenseMatrix());
    }
  }
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
  if (!baro_reference_pa_ && options_.baro.enabled)
    spdlog::warn("estimator: no baro reference pressure (none in setup, no landed baro data): baro unused");
}

void EstimatorNode::initialize(const InitialBelief& b) {
  if (gravity_checks_ == 0 && !gravity_check_at_)
    gravity_check_at_ = b.t + Duration::fromSec(options_.init.motion_window_s);
  auto filter = makeStrategy(options_, gravity_z_sign_);
  filter->reset(setup_.imu_id, b.imu, b.cov, b.t);
  if (options_.baro.enabled && b.baro_reference_pa) {
    baro_reference_pa_ = b.baro_reference_pa;
    filter->addInstance<BaroBiasKind>(setup_.baro_id, b.baro_bias_m, Eigen::MatrixXd::Constant(1, 1, b.baro_bias_var_m2));
  } else if (options_.baro.enabled && resume_kept_ && resume_kept_->baro_reference_pa) {
    baro_reference_pa_ = resume_kept_->baro_reference_pa;  // a restart in flight: the predecessor's
  }                                                        // reference (its bias: a kept instance)
  pending_height_bias_ = b.height_bias;  // the height instance is added at the first usable height
  addSetupAnchorStates(*filter);
  addTagBiasStates(*filter);
  if (resume_kept_) restoreKeptInstances(*filter, *resume_kept_, b.t);  // replace the priors
  resume_kept_.reset();
  cur_.filter = std::move(filter);
  cur_.mean_reading.reset();
  cur_.last_imu = b.last_imu;
  cur_.prev_imu.reset();
  cur_.landed = b.landed;
  cur_.last_zupt = b.t;
  cur_.rest_rate.reset();
  init_time_ = b.t;
  health_.reset(b.t);
  newest_ = newest_ ? std::max(*newest_, b.t) : b.t;
  logInitialization(b);
  applyPendingAnchorInits(b.t);
}

std::string EstimatorNode::waitingFor() const {
  if (initialized()) return "";
  return initializer_->waitingFor() + (aligner_.reason().empty() ? "" : "; " + aligner_.reason());
}

void EstimatorNode::addAlignHeight(const AlignHeight& h) {
  // Thinned to height.align_rate_hz: a vertical constraint, not a trajectory.
  if (options_.height.align_rate_hz <= 0.0) return;
  if (last_align_height_ && (h.t - *last_align_height_).sec() < 1.0 / options_.height.align_rate_hz - 1e-6 &&
      h.t >= *last_align_height_)
    return;
  last_align_height_ = h.t;
  aligner_.addHeight(h);
}

void EstimatorNode::feedAlignerHeight(const HeightSample& h) {
  if (options_.height.enabled && h.range_m >= options_.height.min_range_m)  // usable readings only
    addAlignHeight({h.t, h.range_m, options_.height.sigma_m});
}

void EstimatorNode::feedAlignerBaro(const BaroSample& b) {
  const double ref = *setup_.baro_reference_pressure_pa;
  const double sigma_m = std::abs(atmosphere::dHeightDPressure(b.pressure_pa, ref)) * options_.baro.pressure_sigma_pa;
  addAlignHeight({b.t, atmosphere::heightFromPressure(b.pressure_pa, ref), sigma_m});
}

void EstimatorNode::feedAligner(const EstimatorInput& in) {
  if (const auto* s = std::get_if<ImuSample>(&in)) {
    aligner_.addImu(*s);
    if (carried_height_) feedAlignerHeight(HeightSample{s->t, setup_.carried_height->height_m});
    // Stillness is the evidence of rest only while no flight state was received.
    if (!have_flight_state_ && options_.zupt.detect_stillness) {
      const bool still = still_detector_.add(*s);
      still_at_[s->t.us] = still;
      // Kept for rewinds within the window (also pruned there); bounded while not initialized too.
      const int64_t oldest_us = oldestReplayUs(s->t.us);
      while (!still_at_.empty() && still_at_.begin()->first < oldest_us) still_at_.erase(still_at_.begin());
      if (!initialized()) initializer_->addStillness(still);
    }
  } else if (std::holds_alternative<FlightStateSample>(in)) {
    have_flight_state_ = true;
  } else if (const auto* b = std::get_if<BaroSample>(&in)) {
    last_pressure_pa_ = b->pressure_pa;
    if (baro_aligns_) feedAlignerBaro(*b);
  } else if (const auto* h = std::get_if<HeightSample>(&in)) {
    if (!carried_height_ && !baro_aligns_) feedAlignerHeight(*h);
  } else if (const auto* r = std::get_if<RangeSample>(&in)) {
    SensorId tag = r->id_initiator, anchor = r->id_responder;
    if (!cur_.network->isTag(tag)) std::swap(tag, anchor);
    if (!cur_.network->isTag(tag) || cur_.network->isTag(anchor)) return;
    const Eigen::Vector3d* p = cur_.network->exactAnchor(anchor);
    std::optional<Eigen::Vector3d> p_est;
    if (!p && cur_.filter && cur_.filter->state().values<AnchorKind>().count(anchor))
      p_est = cur_.filter->state().values<AnchorKind>().at(anchor).p_AinG;
    if (!p && !p_est && setup_.abs_anchor_positions.count(anchor)) p_est = setup_.abs_anchor_positions.at(anchor);
    if (!p && !p_est) return;
    const PairBias pb = cur_.network->pairBias(tag, anchor);
    AlignRange a;
    a.t = r->t;
    a.tag = tag;
    a.anchor = anchor;
    a.p_AinG = p ? *p : *p_est;
    a.d_m = ((options_.uwb.use_corrected_range ? r->range_corr_m : r->range_m) - pb.gamma_m) / pb.beta;
    a.sigma_m = cur_.network->rangeSigma(tag, anchor, r->R_m2);
    aligner_.addRange(a);
  }
}

bool EstimatorNode::landedAt(Timestamp t) const {
  if (have_flight_state_ || !options_.zupt.detect_stillness) return cur_.landed;
  auto it = still_at_.find(t.us);
  return it != still_at_.end() && it->second;
}

std::optional<AlignmentResult> EstimatorNode::solveAlignment(const Eigen::Vector3d& bias_gyro_rad_s) {
  ScopedStepTimer timer(timings_, "align");
  return aligner_.solve(bias_gyro_rad_s);
}

void EstimatorNode::tryMotionInitialization(Timestamp t) {
  if (last_align_try_ && (t - *last_align_try_).sec() < 0.5) return;
  last_align_try_ = t;
  const int relinearized_before = aligner_.relinearizations();
  const auto r = solveAlignment(Eigen::Vector3d::Zero());
  if (aligner_.relinearizations() > relinearized_before) diag_.count("init_motion_relinearized");
  if (!r) {
    diag_.count("init_motion_refused");
    return;
  }
  initialize(beliefFromAlignment(*r));
}

InitialBelief EstimatorNode::beliefFromAlignment(const AlignmentResult& r) const {
  InitialBelief b;
  b.t = r.t;
  b.imu = r.imu;
  b.cov = r.cov;
  b.from_ranges = true;
  b.n_ranges_used = r.n_ranges;
  b.range_fit_rms_m = r.rms_m;
  b.last_imu = r.last_imu;
  b.landed = landedAt(r.t);
  if (r.n_heights > 0 && !baro_aligns_) {
    b.height_bias = std::make_pair(r.height_bias_m, r.height_bias_var_m2);
    b.n_heights_used = r.n_heights;
  }
  const double baro_z = (r.imu.p_IinG + r.imu.q_ItoG * setup_.baro_p_IP).z();
  if (setup_.baro_reference_pressure_pa) {
    b.baro_reference_pa = *setup_.baro_reference_pressure_pa;
    b.baro_bias_m = 0.0;
    b.baro_bias_var_m2 = std::pow(options_.baro.init_bias_sigma_m, 2);
    if (baro_aligns_ && r.n_heights > 0) {  // the alignment estimated the baro's bias with the pose
      b.baro_bias_m = r.height_bias_m;
      b.baro_bias_var_m2 = r.height_bias_var_m2;
    }
  } else if (last_pressure_pa_) {  // reference: the current pressure at the aligned height
    b.baro_reference_pa = *last_pressure_pa_;
    b.baro_bias_m = -baro_z;
    b.baro_bias_var_m2 = r.cov(ImuErr::kP + 2, ImuErr::kP + 2) + 0.05;
  }
  return b;
}

void EstimatorNode::propagateFilter(const ImuReading& u, Timestamp t) {
  FusionStrategy& f = *cur_.filter;
  const Timestamp t0 = f.state().t;
  // Held readings beyond max_dt after the last sample: the part of the step in the gap.
  const Timestamp stale_from =
      cur_.last_imu ? std::max(t0, cur_.last_imu->t + Duration::fromSec(options_.imu.max_dt_s)) : t;
  const std::string& mode = options_.imu.gap_readings;
  if (stale_from < t && mode != "held") {  // the string only in a gap
    // In the gap no reading. "held" repeats the last one for the whole gap, which turns a drone's
    // momentary rotation rate into tens of degrees (docs/robustness.md, "IMU gaps"); "mean"
    // repeats the low-passed readings (a steady turn as held, an oscillation averaged out);
    // "still" takes the vehicle as keeping its velocity and attitude (a = 0 in G, ω = 0).
    if (stale_from > t0) propagateFilterStep(u, stale_from);
    const ImuState& x = f.state().imu;
    const bool mean = mode == "mean" && cur_.mean_reading;
    // Acceleration in G (0 for "still") and angular rate, as the readings they would give.
    const Eigen::Vector3d a_G = mean ? cur_.mean_reading->acc_m_s2 : Eigen::Vector3d::Zero();
    ImuReading gap;
    gap.acc_m_s2 = x.bias_acc_m_s2 + x.q_ItoG.conjugate() * (a_G - gravityG());
    // Turning about the vertical at the low-passed rate; no tilting (a vehicle's tilt swings
    // about level: integrating a low-passed tilt rate for seconds leaves the attitude tilted
    // after the gap, and gravity leaks into the position).
    const double yaw_rate = mean ? cur_.mean_reading->gyro_rad_s.z() : 0.0;
    gap.gyro_rad_s = x.bias_gyro_rad_s + x.q_ItoG.conjugate() * Eigen::Vector3d(0.0, 0.0, yaw_rate);
    propagateFilterStep(gap, t);
  } else {
    propagateFilterStep(u, t);
  }
  const double dt = (t - stale_from).sec();
  if (dt <= 0.0) return;
  // Their error as white noise (velocity and attitude random walk; position the integrated
  // velocity noise).
  f.addImuNoise(whiteImuNoise(std::pow(options_.imu.gap_sigma_acc_m_s2, 2),
                              std::pow(options_.imu.gap_sigma_gyro_rad_s, 2), dt));
}

Eigen::Vector3d EstimatorNode::gravityG() const { return {0.0, 0.0, gravity_z_sign_ * options_.gravity_m_s2}; }

void EstimatorNode::updateMeanReading(const ImuSample& s, const std::optional<ImuSample>& previous) {
  const ImuState& x = cur_.filter->state().imu;
  const Eigen::Vector3d a_G = x.q_ItoG * (s.acc_m_s2 - x.bias_acc_m_s2) + gravityG();
  const Eigen::Vector3d w_G = x.q_ItoG * (s.gyro_rad_s - x.bias_gyro_rad_s);
  const double dt = previous ? (s.t - previous->t).sec() : 0.0;
  if (!cur_.mean_reading || dt <= 0.0 || dt > options_.imu.max_dt_s) {  // (re)start after a gap
    cur_.mean_reading = ImuReading{a_G, w_G};
    return;
  }
  const double a = 1.0 - std::exp(-dt / options_.imu.gap_mean_time_constant_s);
  cur_.mean_reading->acc_m_s2 += a * (a_G - cur_.mean_reading->acc_m_s2);
  cur_.mean_reading->gyro_rad_s += a * (w_G - cur_.mean_reading->gyro_rad_s);
}

void EstimatorNode::propagateFilterStep(const ImuReading& u, Timestamp t) {
  FusionStrategy& f = *cur_.filter;
  const Timestamp t0 = f.state().t;
  f.propagate(u.acc_m_s2, u.gyro_rad_s, t);
  // The IMU noise beyond its stated densities that the range innovations show (λ − 1 of it), and
  // an extrapolated reading's own excess (λ times its extra_noise_scale), in one addition.
  const double lambda = cur_.noise_adapter.scale();
  const double extra = lambda - 1.0 + lambda * u.extra_noise_scale;
  if (extra > 0.0 && t > t0)
    f.addImuNoise(whiteImuNoise(extra * std::pow(options_.imu.acc_noise_density, 2),
                                extra * std::pow(options_.imu.gyro_noise_density, 2), (t - t0).sec()));
}

void EstimatorNode::updateHealth(Timestamp t) {
  if (!initialized()) return;
  if (reentry_.since) return;  // ranges are arriving, held for their joint check (at most uwb.reentry_hold_s)
  checkFlightVolume(t);  // after every input: a slide across the plane takes a few tenths of a second
  if (last_health_eval_ && (t - *last_health_eval_).sec() < 0.1) return;
  last_health_eval_ = t;
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
  // Degraded by gating alone, with the accepted ranges fitting, is what NLOS outliers look like:
  // a re-alignment from those ranges is then more likely wrong than the filter (docs/robustness.md).
  const bool compare = options_.recovery.degraded_disagreement_chi2 > 0.0;
  if (health_.health() == Health::Lost ||
      (health_.health() == Health::Degraded && compare && !health_.acceptedRangesFit(t)) ||
      (compare && check_after_gap_until_ && t <= *check_after_gap_until_))
    tryRecover(t);
}

double EstimatorNode::disagreement(const AlignmentResult& r) const {
  const ImuState& x = cur_.filter->state().imu;
  const Eigen::MatrixXd P = cur_.filter->covariance(setup_.imu_id, setup_.imu_id);
  Eigen::Vector4d d;
  d.head<3>() = r.imu.p_IinG - x.p_IinG;
  d(3) = std::remainder(so3::yawOf(r.imu.q_ItoG) - so3::yawOf(x.q_ItoG), 2.0 * M_PI);
  Eigen::Matrix4d S = Eigen::Matrix4d::Zero();
  S.topLeftCorner<3, 3>() = P.block<3, 3>(ImuErr::kP, ImuErr::kP) + r.cov.block<3, 3>(ImuErr::kP, ImuErr::kP);
  S(3, 3) = so3::yawVariance(x.q_ItoG, P.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta)) +
            so3::yawVariance(r.imu.q_ItoG, r.cov.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta));
  return d.dot(S.ldlt().solve(d));
}

void EstimatorNode::tryRecover(Timestamp t) {
  if (!options_.recovery.enabled) return;
  if (last_recovery_try_ && (t - *last_recovery_try_).sec() < options_.recovery.retry_s) return;
  last_recovery_try_ = t;
  const bool lost = health_.health() == Health::Lost;
  const auto r = solveAlignment(cur_.filter->state().imu.bias_gyro_rad_s);
  if (!r) {
    if (!lost) return;  // degraded: nothing to compare with
    diag_.count("recovery_refused");
    spdlog::warn("estimator: lost at t={}, cannot re-initialize yet: {}", formatSeconds(t), aligner_.reason());
    return;
  }
  // Degraded: replace only a filter that the aligned pose contradicts (a runaway not yet gated out).
  if (!lost) {
    const double chi2 = disagreement(*r);
    if (chi2 <= options_.recovery.degraded_disagreement_chi2) return;
    const bool after_gap = check_after_gap_until_ && t <= *check_after_gap_until_;
    diag_.count(after_gap ? "recovery_after_imu_gap" : "recovery_degraded");
    spdlog::warn("estimator: {} at t={} and the aligned pose disagrees (chi2 {:.1f} > {:.1f})",
                 after_gap ? "after an IMU gap" : "degraded", formatSeconds(t), chi2,
                 options_.recovery.degraded_disagreement_chi2);
  }
  const ImuState before = cur_.filter->state().imu;
  replaceImu(r->imu, r->cov, r->t, r->last_imu);
  diag_.count("recovery");
  spdlog::warn("estimator: recovered at t={}: re-initialized from {} ranges and the IMU (moved {:.2f} m, "
               "σ_p {:.2f} m, σ_yaw {:.1f} deg); anchors and bias states kept",
               formatSeconds(r->t), r->n_ranges, (r->imu.p_IinG - before.p_IinG).norm(), r->sigma_p_m,
               r->sigma_yaw_deg);
}

void EstimatorNode::checkFlightVolume(Timestamp t) {
  if (!plane_mirror_) return;
  const FusionStrategy& f = *cur_.filter;
  const ImuState& x = f.state().imu;
  if (!cur_.last_imu) return;
  if (!plane_mirror_->isMirrorImage(x.p_IinG, options_.flight_volume.mirror_margin_m)) {
    constrainToVolumeSide(t);
    return;
  }
  ImuState m = x;
  m.p_IinG = plane_mirror_->mirror(x.p_IinG);
  m.v_IinG = plane_mirror_->reflection() * x.v_IinG;
  ImuMatrix J = ImuMatrix::Identity();
  J.block<3, 3>(ImuErr::kP, ImuErr::kP) = plane_mirror_->reflection();
  J.block<3, 3>(ImuErr::kV, ImuErr::kV) = plane_mirror_->reflection();
  const ImuMatrix P = J * f.covariance(setup_.imu_id, setup_.imu_id) * J.transpose();
  diag_.count("mirrored_into_flight_volume");
  spdlog::warn("estimator: at t={} the estimate [{:.2f}, {:.2f}, {:.2f}] m is {:.2f} m outside the flight volume and "
               "its mirror image across the known anchors' plane is inside: taken as the mirror image (moved {:.2f} m)",
               formatSeconds(t), x.p_IinG.x(), x.p_IinG.y(), x.p_IinG.z(),
               setup_.flight_volume->distanceOutside(x.p_IinG), (m.p_IinG - x.p_IinG).norm());
  replaceImu(m, P, f.state().t, *cur_.last_imu);
}

void EstimatorNode::constrainToVolumeSide(Timestamp t) {
  const double rate = options_.flight_volume.side_constraint_rate_hz;
  if (rate <= 0.0 || (last_side_constraint_ && (t - *last_side_constraint_).sec() < 1.0 / rate - 1e-9)) return;
  last_side_constraint_ = t;
  FusionStrategy& f = *cur_.filter;
  const Eigen::Vector3d n = plane_mirror_->inwardNormal();
  const double mu = plane_mirror_->inwardDistance(f.state().imu.p_IinG);
  const Eigen::Matrix3d P_pp = f.covariance(setup_.imu_id, setup_.imu_id).block<3, 3>(ImuErr::kP, ImuErr::kP);
  const auto c = AnchorPlaneMirror::sideConstraint(mu, n.dot(P_pp * n));
  if (!c) return;
  Linearization lin;  // r = z − nᵀ(p̂ − c_plane), H = nᵀ on δp
  lin.residual = Eigen::VectorXd::Constant(1, c->z - mu);
  lin.R = Eigen::MatrixXd::Constant(1, 1, c->R);
  JacobianBlock b{setup_.imu_id, Eigen::MatrixXd::Zero(1, ImuErr::kDim)};
  b.H.block<1, 3>(0, ImuErr::kP) = n.transpose();
  lin.blocks.push_back(std::move(b));
  f.update(lin, 0.0);  // not gated: a constraint, not a sensor
  diag_.count("flight_volume_side_constraint");
}

void EstimatorNode::replaceImu(const ImuState& x, const ImuMatrix& P, Timestamp t, const ImuSample& last_imu) {
  cur_.mean_reading.reset();  // low-passed in the attitude and gravity being replaced
  const FusionStrategy& old = *cur_.filter;
  const NominalState& s = old.state();
  auto f = makeStrategy(options_, gravity_z_sign_);
  f->reset(setup_.imu_id, x, P, t);
  // Every instance keeps its mean; its marginal covariance as its kind says (the baro bias, which
  // may have absorbed the runaway, is widened to the init σ; tag γ keep their variances).
  forEachKind([&]<class K>() {
    if constexpr (!K::kBody)
      for (const auto& [id, value] : s.values<K>())
        f->addInstance<K>(id, value, K::keptCovariance(old.covariance(id, id), options_));
  });
  // DAH joint sets stay together (their members' cross-covariances restart from zero like all others).
  forEachKind([&]<class K>() {
    if constexpr (!K::kBody)
      for (const auto& [id, value] : s.values<K>())
        if (const std::vector<SensorId> set = old.jointSetOf(id); !set.empty()) f->joinJointSet(set);
  });
  cur_.filter = std::move(f);
  cur_.last_imu = last_imu;
  cur_.prev_imu.reset();
  cur_.last_zupt = t;
  cur_.rest_rate.reset();
  history_.clear();  // a rewind must not restore the state before the re-initialization
  clearRerunHistory();  // nor a re-run (it starts from the new pose, with the anchors it has)
  reentry_ = ReentryHold{};  // held ranges were in the history; the new pose comes from ranges
  last_tag_range_accepted_ = t;
  init_time_ = t;
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
