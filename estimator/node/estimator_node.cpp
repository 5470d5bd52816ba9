#include "estimator/node/estimator_node.h"

#include <spdlog/spdlog.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "common/atmosphere.h"
#include "estimator/filter/strategy_factory.h"
#include "estimator/uwb/range_model.h"

namespace meshnav::estimator {

namespace {

std::string where(const char* channel, Timestamp t) { return std::string(channel) + " t=" + formatSeconds(t); }

}  // namespace

std::vector<EstimatorInput> mergeInTimeOrder(const Dataset& ds) {
  std::vector<EstimatorInput> all;
  all.reserve(ds.imu.size() + ds.baro.size() + ds.ranges.size() + ds.flight_states.size());
  for (const auto& s : ds.flight_states) all.emplace_back(s);
  for (const auto& s : ds.imu) all.emplace_back(s);
  for (const auto& s : ds.baro) all.emplace_back(s);
  for (const auto& s : ds.ranges) all.emplace_back(s);
  std::stable_sort(all.begin(), all.end(),
                   [](const EstimatorInput& a, const EstimatorInput& b) { return inputOrder(a) < inputOrder(b); });
  return all;
}

EstimatorNode::Snapshot EstimatorNode::Snapshot::copy() const {
  Snapshot s;
  s.filter = filter ? filter->clone() : nullptr;
  s.network = network;
  s.last_imu = last_imu;
  s.landed = landed;
  s.last_zupt = last_zupt;
  return s;
}

namespace {
EstimatorOptions withSetupNoise(EstimatorOptions o, const SystemSetup& setup) {
  o.applySetupNoise(setup.noise);
  return o;
}

MotionAlignerOptions alignerOptions(const EstimatorOptions& o) {
  MotionAlignerOptions a;
  a.window_s = o.init.motion_window_s;
  a.min_span_s = o.init.motion_min_span_s;
  a.min_ranges = o.init.motion_min_ranges;
  a.max_sigma_yaw_deg = o.init.motion_max_sigma_yaw_deg;
  a.max_sigma_p_m = o.init.motion_max_sigma_p_m;
  a.sigma_bias_acc_m_s2 = o.init.sigma_bias_acc_m_s2;
  a.sigma_bias_gyro_rad_s = o.init.sigma_bias_gyro_rad_s;
  a.outlier_m = o.init.range_init_outlier_m;
  a.ambiguity_chi2 = o.init.ambiguity_chi2;
  a.gravity_m_s2 = o.gravity_m_s2;
  a.max_imu_gap_s = o.imu.max_dt_s;
  return a;
}

/// Largest principal position σ [m] and its direction (G).
std::pair<double, Eigen::Vector3d> weakestPositionAxis(const Eigen::Matrix3d& P) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(0.5 * (P + P.transpose()));
  return {std::sqrt(std::max(es.eigenvalues()(2), 0.0)), es.eigenvectors().col(2)};
}
}  // namespace

EstimatorNode::EstimatorNode(const EstimatorOptions& options, const SystemSetup& setup, EstimatorSinks sinks)
    : options_(withSetupNoise(options, setup)),
      setup_(setup),
      sinks_(std::move(sinks)),
      baro_model_(setup.baro_p_IP),
      zupt_model_(Eigen::Vector3d(0.0, 0.0, -options.gravity_m_s2)),
      aligner_(alignerOptions(options_), setup.rel_tag_positions),
      still_detector_(StillnessOptions{}, options_.imu.acc_noise_density, options_.imu.gyro_noise_density,
                      options_.gravity_m_s2),
      health_(options_.health) {
  options_.validate();
  if (!strategyImplemented(options_.strategy))
    throw std::invalid_argument("strategy '" + options_.strategy + "' is not implemented yet (next issue)");
  if (options_.uwb.gate_probability > 0) range_gate_ = chi2Quantile(1, options_.uwb.gate_probability);
  skip_estimated_anchor_pairs_ = options_.strategy == "dah" && !options_.uwb.dah_fuse_estimated_anchor_pairs;
  if (options_.baro.gate_probability > 0) baro_gate_ = chi2Quantile(1, options_.baro.gate_probability);
  resetAll();
}

EstimatorNode::~EstimatorNode() = default;

void EstimatorNode::resetAll() {
  initializer_ = std::make_unique<StaticInitializer>(options_, setup_);
  aligner_.clear();
  last_align_try_.reset();
  last_recovery_try_.reset();
  cur_ = Snapshot{};
  cur_.network = std::make_shared<const UwbNetwork>(setup_, options_.uwb.sigma_range_m);
  history_.clear();
  baro_reference_pa_.reset();
  instance_stats_.clear();
  last_pose_pub_.reset();
}

void EstimatorNode::event(bool first, const std::string& kind, const std::string& message) {
  if (!first) return;
  if (message.empty())
    diag_.count(kind);
  else
    diag_.report(kind, message);
}

bool EstimatorNode::validate(const EstimatorInput& in) {
  std::string bad;
  Timestamp t = inputTime(in);
  if (const auto* s = std::get_if<ImuSample>(&in)) {
    if (!s->acc_m_s2.allFinite() || !s->gyro_rad_s.allFinite() || s->acc_m_s2.norm() > 2000.0 ||
        s->gyro_rad_s.norm() > 100.0)
      bad = where("IMU", t) + ": non-finite or absurd reading";
  } else if (const auto* s = std::get_if<BaroSample>(&in)) {
    if (!std::isfinite(s->pressure_pa) || s->pressure_pa < 1000.0 || s->pressure_pa > 200000.0)
      bad = where("BARO", t) + ": non-finite or absurd pressure " + std::to_string(s->pressure_pa);
  } else if (const auto* s = std::get_if<RangeSample>(&in)) {
    const double z = options_.uwb.use_corrected_range ? s->range_corr_m : s->range_m;
    if (!std::isfinite(z) || z < -0.5 || z > options_.uwb.max_range_m || !std::isfinite(s->R_m2) || s->R_m2 < 0)
      bad = where("RANGE", t) + ": bad range " + std::to_string(z) + " m between " + std::to_string(s->id_initiator) +
            " and " + std::to_string(s->id_responder);
    else if (s->id_initiator == s->id_responder || s->id_initiator <= 0 || s->id_responder <= 0)
      bad = where("RANGE", t) + ": invalid ids " + std::to_string(s->id_initiator) + ", " +
            std::to_string(s->id_responder);
  } else if (const auto* a = std::get_if<AnchorInit>(&in)) {
    if (a->id <= 0 || !a->p_AinG.allFinite() || !a->cov_p_m2.allFinite() ||
        Eigen::LLT<Eigen::Matrix3d>(0.5 * (a->cov_p_m2 + a->cov_p_m2.transpose())).info() != Eigen::Success)
      bad = where("ANCHOR_INIT", t) + ": anchor " + std::to_string(a->id) + " with invalid position or covariance";
    for (const auto& b : a->biases)
      if (!std::isfinite(b.gamma_m) || !std::isfinite(b.beta) || b.beta <= 0.0 || !std::isfinite(b.sigma_m))
        bad = where("ANCHOR_INIT", t) + ": anchor " + std::to_string(a->id) + " with invalid pair bias";
  }
  if (!bad.empty()) {
    diag_.report("bad_input", bad);
    return false;
  }
  return true;
}

void EstimatorNode::onInput(const EstimatorInput& in_raw) {
  if (!validate(in_raw)) return;
  EstimatorInput in = in_raw;
  // Commands are not measurements: they apply now (at the newest time) unless they are newer.
  if (newest_ && (std::holds_alternative<AnchorInit>(in) || std::holds_alternative<EstimatorCommand>(in))) {
    if (auto* a = std::get_if<AnchorInit>(&in)) a->t = std::max(a->t, *newest_);
    if (auto* c = std::get_if<EstimatorCommand>(&in)) c->t = std::max(c->t, *newest_);
  }
  if (const auto* c = std::get_if<EstimatorCommand>(&in); c && c->action == EstimatorCommand::Action::Reset) {
    spdlog::info("estimator: reset by command at t={}", formatSeconds(c->t));
    diag_.count("reset");
    resetAll();
    return;
  }
  const Timestamp t = inputTime(in);
  feedAligner(in);
  if (!initialized()) {
    newest_ = newest_ ? std::max(*newest_, t) : t;
    feedInitializer(in);
    publishPeriodic();
    return;
  }
  if (t < init_time_) {
    diag_.count("before_init");
    return;
  }
  if (t < *newest_ - Duration::fromSec(options_.window_s)) {
    diag_.report("rejected_too_old", where("input", t) + " is older than the newest " + formatSeconds(*newest_) +
                                         " minus the window " + std::to_string(options_.window_s) + " s");
    return;
  }
  Entry e{inputOrder(in), in, nullptr};
  auto pos = std::upper_bound(history_.begin(), history_.end(), e.key,
                              [](const InputOrder& k, const Entry& x) { return k < x.key; });
  if (pos == history_.end()) {
    e.before = std::make_shared<const Snapshot>(cur_.copy());
    history_.push_back(std::move(e));
    process(history_.back().input, true);
  } else {
    // Out of sequence: rewind to the snapshot before its place, re-process in order.
    diag_.count("out_of_sequence");
    ScopedStepTimer rewind_timer(timings_, "rewind");
    cur_ = pos->before->copy();
    e.before = pos->before;
    auto it = history_.insert(pos, std::move(e));
    process(it->input, true);
    for (++it; it != history_.end(); ++it) {
      it->before = std::make_shared<const Snapshot>(cur_.copy());
      process(it->input, false);
    }
  }
  newest_ = std::max(*newest_, t);
  const Timestamp oldest_kept = *newest_ - Duration::fromSec(options_.window_s);
  while (!history_.empty() && history_.front().key.t_us < oldest_kept.us) history_.pop_front();
  while (!still_at_.empty() && still_at_.begin()->first < oldest_kept.us) still_at_.erase(still_at_.begin());
  updateHealth(*newest_);
  publishPeriodic();
}

void EstimatorNode::feedAligner(const EstimatorInput& in) {
  if (const auto* s = std::get_if<ImuSample>(&in)) {
    aligner_.addImu(*s);
    // Stillness is the evidence of rest only while no flight state was received.
    if (!have_flight_state_ && options_.zupt.detect_stillness) {
      const bool still = still_detector_.add(*s);
      still_at_[s->t.us] = still;
      if (!initialized()) initializer_->addStillness(still);
    }
  } else if (std::holds_alternative<FlightStateSample>(in)) {
    have_flight_state_ = true;
  } else if (const auto* b = std::get_if<BaroSample>(&in)) {
    last_pressure_pa_ = b->pressure_pa;
  } else if (const auto* r = std::get_if<RangeSample>(&in)) {
    SensorId tag = r->id_initiator, anchor = r->id_responder;
    if (!cur_.network->isTag(tag)) std::swap(tag, anchor);
    if (!cur_.network->isTag(tag) || cur_.network->isTag(anchor)) return;
    const Eigen::Vector3d* p = cur_.network->exactAnchor(anchor);
    std::optional<Eigen::Vector3d> p_est;
    if (!p && cur_.filter && cur_.filter->state().anchor_p_AinG.count(anchor))
      p_est = cur_.filter->state().anchor_p_AinG.at(anchor);
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

std::string EstimatorNode::waitingFor() const {
  if (initialized()) return "";
  return initializer_->waitingFor() + (aligner_.reason().empty() ? "" : "; " + aligner_.reason());
}

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
          if (m.action == EstimatorCommand::Action::AddAnchor) pending_anchor_inits_.push_back(m.anchor);
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

void EstimatorNode::tryMotionInitialization(Timestamp t) {
  if (last_align_try_ && (t - *last_align_try_).sec() < 0.5) return;
  last_align_try_ = t;
  const auto r = aligner_.solve(Eigen::Vector3d::Zero());
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
  const double baro_z = (r.imu.p_IinG + r.imu.q_ItoG * setup_.baro_p_IP).z();
  if (setup_.baro_reference_pressure_pa) {
    b.baro_reference_pa = *setup_.baro_reference_pressure_pa;
    b.baro_bias_m = 0.0;
    b.baro_bias_var_m2 = std::pow(options_.baro.init_bias_sigma_m, 2);
  } else if (last_pressure_pa_) {  // reference: the current pressure at the aligned height
    b.baro_reference_pa = *last_pressure_pa_;
    b.baro_bias_m = -baro_z;
    b.baro_bias_var_m2 = r.cov(ImuErr::kP + 2, ImuErr::kP + 2) + 0.05;
  }
  return b;
}

void EstimatorNode::initialize(const InitialBelief& b) {
  auto filter = makeStrategy(options_);
  filter->reset(setup_.imu_id, b.imu, b.cov, b.t);
  if (options_.baro.enabled && b.baro_reference_pa) {
    baro_reference_pa_ = b.baro_reference_pa;
    filter->addBaro(setup_.baro_id, b.baro_bias_m, b.baro_bias_var_m2);
  }
  for (const auto& [id, p] : setup_.abs_anchor_positions) {
    auto sig = setup_.abs_anchor_sigmas_m.find(id);
    if (sig != setup_.abs_anchor_sigmas_m.end())
      filter->addAnchor(id, p, Eigen::Matrix3d::Identity() * sig->second * sig->second);
  }
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
        filter->addTagBiases(tag, peers, Eigen::Map<Eigen::VectorXd>(gamma.data(), static_cast<long>(gamma.size())),
                             Eigen::Map<Eigen::VectorXd>(var.data(), static_cast<long>(var.size())));
    }
  }
  cur_.filter = std::move(filter);
  cur_.last_imu = b.last_imu;
  cur_.landed = b.landed;
  cur_.last_zupt = b.t;
  init_time_ = b.t;
  health_.reset(b.t);
  newest_ = newest_ ? std::max(*newest_, b.t) : b.t;
  const Eigen::Matrix3d R0 = b.imu.q_ItoG.toRotationMatrix();
  const double yaw_deg = std::atan2(R0(1, 0), R0(0, 0)) * 180.0 / M_PI;
  spdlog::info(
      "estimator: initialized at t={} from {} p_IinG=[{:.3f}, {:.3f}, {:.3f}] m, yaw {:.1f} deg (σ_p {:.2f} m, "
      "σ_yaw {:.1f} deg){}",
      formatSeconds(b.t), b.from_ranges ? "ranges" : "initial_pose", b.imu.p_IinG.x(), b.imu.p_IinG.y(),
      b.imu.p_IinG.z(), yaw_deg, weakestPositionAxis(b.cov.block<3, 3>(ImuErr::kP, ImuErr::kP)).first,
      std::sqrt((R0.transpose() * Eigen::Vector3d::UnitZ())
                    .dot(b.cov.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) * (R0.transpose() * Eigen::Vector3d::UnitZ()))) *
          180.0 / M_PI,
      b.from_ranges ? fmt::format(", {} ranges, rms {:.3f} m", b.n_ranges_used, b.range_fit_rms_m) : "");
  if (!baro_reference_pa_ && options_.baro.enabled)
    spdlog::warn("estimator: no baro reference pressure (none in setup, no landed baro data): baro unused");
  const auto pending = std::move(pending_anchor_inits_);
  pending_anchor_inits_.clear();
  for (auto a : pending) {
    a.t = b.t;
    onInput(a);
  }
}

void EstimatorNode::process(const EstimatorInput& in, bool first) {
  std::visit(
      [&](const auto& m) {
        using T = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<T, ImuSample>) processImu(m, first);
        if constexpr (std::is_same_v<T, BaroSample>) processBaro(m, first);
        if constexpr (std::is_same_v<T, RangeSample>) processRange(m, first);
        if constexpr (std::is_same_v<T, FlightStateSample>) cur_.landed = m.landed;
        if constexpr (std::is_same_v<T, AnchorInit>) applyAnchorInit(m, first);
        if constexpr (std::is_same_v<T, EstimatorCommand>) applyCommand(m, first);
      },
      in);
}

void EstimatorNode::propagateTo(Timestamp t) {
  if (!cur_.last_imu || t <= cur_.filter->state().t) return;
  ScopedStepTimer timer(timings_, "propagate");
  propagateFilter(cur_.last_imu->acc_m_s2, cur_.last_imu->gyro_rad_s, t);
}

void EstimatorNode::propagateFilter(const Eigen::Vector3d& acc, const Eigen::Vector3d& gyro, Timestamp t) {
  FusionStrategy& f = *cur_.filter;
  const Timestamp t0 = f.state().t;
  f.propagate(acc, gyro, t);
  if (!cur_.last_imu) return;
  // Held readings beyond max_dt after the last sample: their error as white noise (velocity and
  // attitude random walk; position gets the integrated velocity noise).
  const Timestamp stale_from = std::max(t0, cur_.last_imu->t + Duration::fromSec(options_.imu.max_dt_s));
  const double dt = (t - stale_from).sec();
  if (dt <= 0.0) return;
  const double qa = std::pow(options_.imu.gap_sigma_acc_m_s2, 2), qw = std::pow(options_.imu.gap_sigma_gyro_rad_s, 2);
  ImuMatrix Q = ImuMatrix::Zero();
  const Eigen::Matrix3d I3 = Eigen::Matrix3d::Identity();
  Q.block<3, 3>(ImuErr::kP, ImuErr::kP) = I3 * qa * dt * dt * dt / 3.0;
  Q.block<3, 3>(ImuErr::kP, ImuErr::kV) = Q.block<3, 3>(ImuErr::kV, ImuErr::kP) = I3 * qa * dt * dt / 2.0;
  Q.block<3, 3>(ImuErr::kV, ImuErr::kV) = I3 * qa * dt;
  Q.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) = I3 * qw * dt;
  f.addImuNoise(Q);
}

void EstimatorNode::processImu(const ImuSample& s, bool first) {
  FusionStrategy& f = *cur_.filter;
  const Timestamp t0 = f.state().t;
  // Gaps on the IMU's own time line (range and baro updates move the filter's time meanwhile).
  if (cur_.last_imu && (s.t - cur_.last_imu->t).sec() > options_.imu.max_dt_s)
    event(first, "imu_gap",
          where("IMU", s.t) + ": no IMU sample for " + std::to_string((s.t - cur_.last_imu->t).sec()) +
              " s; propagated on held readings with inflated noise");
  if (s.t > t0) {
    // Readings interpolated to the middle of [t0, s.t] (held when no earlier reading).
    Eigen::Vector3d acc = s.acc_m_s2, gyro = s.gyro_rad_s;
    if (cur_.last_imu && s.t > cur_.last_imu->t) {
      const double alpha = 0.5 * ((t0 - cur_.last_imu->t).sec() + (s.t - cur_.last_imu->t).sec()) /
                           (s.t - cur_.last_imu->t).sec();
      acc = (1.0 - alpha) * cur_.last_imu->acc_m_s2 + alpha * s.acc_m_s2;
      gyro = (1.0 - alpha) * cur_.last_imu->gyro_rad_s + alpha * s.gyro_rad_s;
    }
    ScopedStepTimer timer(timings_, "propagate");
    propagateFilter(acc, gyro, s.t);
  }
  cur_.last_imu = s;
  if (!have_flight_state_) cur_.landed = landedAt(s.t);
  if (options_.zupt.enabled && cur_.landed && (s.t - cur_.last_zupt).sec() >= 1.0 / options_.zupt.rate_hz - 1e-9) {
    ScopedStepTimer timer(timings_, "zupt");
    ZuptMeasurement z;
    z.t = s.t;
    z.acc_m_s2 = s.acc_m_s2;
    z.gyro_rad_s = s.gyro_rad_s;
    z.sigma_acc_m_s2 = options_.zupt.sigma_acc_m_s2;
    z.sigma_gyro_rad_s = options_.zupt.sigma_gyro_rad_s;
    z.sigma_vel_m_s = options_.zupt.sigma_vel_m_s;
    const Linearization lin = zupt_model_.linearize(z, f.state());
    const double gate = have_flight_state_ ? 0.0 : chi2Quantile(static_cast<int>(lin.residual.size()),
                                                                options_.zupt.stillness_gate_probability);
    if (!f.update(lin, gate).accepted) event(first, "gated_zupt");
    cur_.last_zupt = s.t;
    if (first) ++instance_stats_[setup_.imu_id].n_updates;
  }
  if (first && sinks_.pose) {
    const bool due = options_.pose_output_rate_hz <= 0.0 || !last_pose_pub_ ||
                     (s.t - *last_pose_pub_).sec() >= 1.0 / options_.pose_output_rate_hz - 1e-6;
    if (due) {
      last_pose_pub_ = s.t;
      sinks_.pose(makePose());
    }
  }
}

void EstimatorNode::processBaro(const BaroSample& s, bool first) {
  if (!options_.baro.enabled) return;
  if (!baro_reference_pa_) {
    event(first, "baro_no_reference");
    return;
  }
  propagateTo(s.t);
  ScopedStepTimer timer(timings_, "baro_update");
  BaroMeasurement z;
  z.t = s.t;
  z.baro_id = setup_.baro_id;
  z.height_m = atmosphere::heightFromPressure(s.pressure_pa, *baro_reference_pa_);
  z.sigma_m = std::abs(atmosphere::dHeightDPressure(s.pressure_pa, *baro_reference_pa_)) * options_.baro.pressure_sigma_pa;
  const UpdateResult r = cur_.filter->update(baro_model_.linearize(z, cur_.filter->state()), baro_gate_);
  if (!first) return;
  InstanceStatus& st = instance_stats_[setup_.baro_id];
  health_.onUpdate(s.t, "baro", 0, r.accepted, r.nis);
  if (r.accepted) {
    ++st.n_updates;
  } else {
    ++st.n_rejected;
    diag_.count("gated_baro");
  }
}

void EstimatorNode::processRange(const RangeSample& s, bool first) {
  if (!options_.uwb.enabled) return;
  RangeMeasurement z;
  z.t = s.t;
  z.a = s.id_initiator;
  z.b = s.id_responder;
  z.z_m = options_.uwb.use_corrected_range ? s.range_corr_m : s.range_m;
  z.R_m2 = s.R_m2;
  const RangeModel::Status status = RangeModel::classify(z, cur_.filter->state(), *cur_.network);
  if (status != RangeModel::Status::Ok) {
    if (status == RangeModel::Status::UnknownId)
      event(first, "unknown_id",
            where("RANGE", s.t) + ": unknown device in range " + std::to_string(z.a) + "–" + std::to_string(z.b));
    else
      event(first, RangeModel::statusName(status));
    return;
  }
  if (skip_estimated_anchor_pairs_ && cur_.filter->state().anchor_p_AinG.count(z.a) &&
      cur_.filter->state().anchor_p_AinG.count(z.b)) {
    event(first, "range_dah_anchor_pair_skipped");  // a policy, not bad input (see UwbOptions)
    return;
  }
  propagateTo(s.t);
  ScopedStepTimer timer(timings_, "range_update");
  Linearization lin;
  const RangeModel::Status st = RangeModel::linearize(z, cur_.filter->state(), *cur_.network, &lin);
  if (st != RangeModel::Status::Ok) {
    event(first, RangeModel::statusName(st));
    return;
  }
  const UpdateResult r = cur_.filter->update(lin, range_gate_);
  if (!first) return;
  if (!r.accepted) diag_.count("gated_range");
  // Tag ranges tell whether the pose is right; ranges between anchors do not.
  if (cur_.network->isTag(z.a) || cur_.network->isTag(z.b))
    health_.onUpdate(s.t, "range", cur_.network->isTag(z.a) ? z.b : z.a, r.accepted, r.nis);
  else
    health_.onUpdate(s.t, "anchor_range", 0, r.accepted, r.nis);
  for (SensorId id : {z.a, z.b}) {
    InstanceStatus& is = instance_stats_[id];
    ++(r.accepted ? is.n_updates : is.n_rejected);
  }
}

void EstimatorNode::applyAnchorInit(const AnchorInit& a, bool first) {
  auto net = std::make_shared<UwbNetwork>(*cur_.network);
  if (net->isTag(a.id)) {
    event(first, "bad_command", where("ANCHOR_INIT", a.t) + ": id " + std::to_string(a.id) + " is a tag");
    return;
  }
  net->removeDevice(a.id);  // an exactly known anchor becomes an estimated one
  for (PairBias b : a.biases) {
    if (b.a != a.id && b.b != a.id) b.b = a.id;
    net->setPairBias(b);
  }
  cur_.network = std::move(net);
  cur_.filter->addAnchor(a.id, a.p_AinG, 0.5 * (a.cov_p_m2 + a.cov_p_m2.transpose()));
  if (first) {
    diag_.count("anchor_init");
    spdlog::info("estimator: anchor {} added at t={} p_AinG=[{:.3f}, {:.3f}, {:.3f}] with {} pair biases", a.id,
                 formatSeconds(a.t), a.p_AinG.x(), a.p_AinG.y(), a.p_AinG.z(), a.biases.size());
  }
}

void EstimatorNode::applyCommand(const EstimatorCommand& c, bool first) {
  switch (c.action) {
    case EstimatorCommand::Action::AddAnchor: {
      AnchorInit a = c.anchor;
      a.id = c.id ? c.id : a.id;
      a.t = c.t;
      applyAnchorInit(a, first);
      break;
    }
    case EstimatorCommand::Action::RemoveInstance: {
      if (c.id == setup_.imu_id || c.id == setup_.baro_id) {
        event(first, "bad_command", "ESTIMATOR_CMD: cannot remove the IMU or baro instance " + std::to_string(c.id));
        break;
      }
      bool removed = cur_.filter->removeInstance(c.id);
      if (cur_.network->isTag(c.id) || cur_.network->exactAnchor(c.id)) {
        auto net = std::make_shared<UwbNetwork>(*cur_.network);
        removed = net->removeDevice(c.id) || removed;
        cur_.network = std::move(net);
      }
      if (!removed) event(first, "bad_command", "ESTIMATOR_CMD: no instance " + std::to_string(c.id) + " to remove");
      break;
    }
    case EstimatorCommand::Action::Reset: break;  // handled in onInput
  }
}

void EstimatorNode::updateHealth(Timestamp t) {
  if (!initialized()) return;
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
  if (health_.health() == Health::Lost) tryRecover(t);
}

void EstimatorNode::tryRecover(Timestamp t) {
  if (!options_.recovery.enabled) return;
  if (last_recovery_try_ && (t - *last_recovery_try_).sec() < options_.recovery.retry_s) return;
  last_recovery_try_ = t;
  const auto r = aligner_.solve(cur_.filter->state().imu.bias_gyro_rad_s);
  if (!r) {
    diag_.count("recovery_refused");
    spdlog::warn("estimator: lost at t={}, cannot re-initialize yet: {}", formatSeconds(t), aligner_.reason());
    return;
  }
  const ImuState before = cur_.filter->state().imu;
  replaceImu(r->imu, r->cov, r->t, r->last_imu);
  diag_.count("recovery");
  spdlog::warn("estimator: recovered at t={}: re-initialized from {} ranges and the IMU (moved {:.2f} m, "
               "σ_p {:.2f} m, σ_yaw {:.1f} deg); anchors and bias states kept",
               formatSeconds(r->t), r->n_ranges, (r->imu.p_IinG - before.p_IinG).norm(), r->sigma_p_m,
               r->sigma_yaw_deg);
}

void EstimatorNode::replaceImu(const ImuState& x, const ImuMatrix& P, Timestamp t, const ImuSample& last_imu) {
  const FusionStrategy& old = *cur_.filter;
  const NominalState& s = old.state();
  auto f = makeStrategy(options_);
  f->reset(setup_.imu_id, x, P, t);
  // The baro bias may have absorbed the runaway: keep its mean, widen it to the init σ.
  for (const auto& [id, b] : s.baro_bias_m)
    f->addBaro(id, b, std::max(old.covariance(id, id)(0, 0), std::pow(options_.baro.init_bias_sigma_m, 2)));
  for (const auto& [id, p] : s.anchor_p_AinG) f->addAnchor(id, p, old.covariance(id, id));
  for (const auto& [id, tb] : s.tag_biases)
    f->addTagBiases(id, tb.peers, tb.gamma_m, old.covariance(id, id).diagonal());
  cur_.filter = std::move(f);
  cur_.last_imu = last_imu;
  cur_.last_zupt = t;
  history_.clear();  // a rewind must not restore the state before the re-initialization
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

PoseEstimate EstimatorNode::makePose() const {
  const FusionStrategy& f = *cur_.filter;
  const NominalState& x = f.state();
  const Eigen::MatrixXd P = f.covariance(x.imu_id, x.imu_id);
  PoseEstimate e;
  e.t = x.t;
  e.p_IinG = x.imu.p_IinG;
  e.v_IinG = x.imu.v_IinG;
  e.q_ItoG = x.imu.q_ItoG;
  e.bias_gyro_rad_s = x.imu.bias_gyro_rad_s;
  e.bias_acc_m_s2 = x.imu.bias_acc_m_s2;
  e.cov_p_m2 = P.block<3, 3>(ImuErr::kP, ImuErr::kP);
  e.cov_v = P.block<3, 3>(ImuErr::kV, ImuErr::kV);
  e.cov_theta_rad2 = P.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta);
  return e;
}

std::optional<PoseEstimate> EstimatorNode::pose() const {
  if (!initialized()) return std::nullopt;
  return makePose();
}

std::vector<AnchorEstimate> EstimatorNode::anchors() const {
  std::vector<AnchorEstimate> out;
  if (!initialized()) return out;
  const NominalState& x = cur_.filter->state();
  for (const auto& [id, p] : cur_.network->exactAnchors()) out.push_back({x.t, id, p, Eigen::Matrix3d::Zero()});
  for (const auto& [id, p] : x.anchor_p_AinG) out.push_back({x.t, id, p, cur_.filter->covariance(id, id)});
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
  return out;
}

EstimatorStatus EstimatorNode::status() const {
  EstimatorStatus s;
  s.t = newest_.value_or(Timestamp{});
  s.wall_utime = std::chrono::duration_cast<std::chrono::microseconds>(
                     std::chrono::system_clock::now().time_since_epoch())
                     .count();
  s.initialized = initialized();
  s.strategy = options_.strategy;
  auto add = [&](SensorId id, const std::string& type) {
    InstanceStatus is;
    auto it = instance_stats_.find(id);
    if (it != instance_stats_.end()) is = it->second;
    is.id = id;
    is.type = type;
    s.instances.push_back(is);
  };
  if (initialized()) {
    for (const StateBlock& b : cur_.filter->layout().blocks()) add(b.id, kindName(b.kind));
    // Tags without state (no estimated biases) are instances too; list each instance once.
    for (const auto& [id, p] : cur_.network->tags())
      if (!cur_.filter->layout().find(id)) add(id, "tag");
    for (const auto& [id, p] : cur_.network->exactAnchors()) add(id, "anchor");
  }
  s.counters = diag_.snapshot();
  s.mean_step_us = timings_.means();
  s.health = healthName(health());
  s.health_reason = initialized() ? health_.reason() : waitingFor();
  if (initialized()) {
    const Eigen::MatrixXd P = cur_.filter->covariance(setup_.imu_id, setup_.imu_id);
    const auto [sigma_p, axis] = weakestPositionAxis(P.block<3, 3>(ImuErr::kP, ImuErr::kP));
    s.sigma_p_max_m = sigma_p;
    s.weak_axis_G = axis;
    const Eigen::Vector3d n = cur_.filter->state().imu.q_ItoG.conjugate() * Eigen::Vector3d::UnitZ();
    s.sigma_yaw_deg = std::sqrt(std::max(n.dot(P.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) * n), 0.0)) * 180.0 / M_PI;
  }
  return s;
}

void EstimatorNode::publishPeriodic() {
  if (!newest_) return;
  const Timestamp now = *newest_;
  auto due = [&](std::optional<Timestamp>& next, double rate_hz) {
    if (next && now < *next) return false;
    const Duration period = Duration::fromSec(1.0 / rate_hz);
    next = (next && now - *next < period) ? *next + period : now + period;
    return true;
  };
  if (initialized() && sinks_.anchors && due(next_anchor_pub_, options_.anchors_output_rate_hz))
    sinks_.anchors(anchors());
  if (sinks_.status && due(next_status_pub_, options_.status_rate_hz)) sinks_.status(status());
}

}  // namespace meshnav::estimator
