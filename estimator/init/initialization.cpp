/// @file initialization.cpp
/// @brief Initialization: the landed initializer, the in-motion alignment and what feeds them
/// (initialization.h).

#include "estimator/init/initialization.h"

#include <cmath>

#include <spdlog/spdlog.h>

#include "common/atmosphere.h"

namespace meshnav::estimator {

bool carriedHeightUsed(const EstimatorOptions& o, const SystemSetup& setup) {
  return setup.carried_height && o.carried_height.enabled;
}

bool baroAligns(const EstimatorOptions& o, const SystemSetup& setup) {
  return o.init.motion_use_baro && !carriedHeightUsed(o, setup) && setup.baro_reference_pressure_pa && o.baro.enabled;
}

Eigen::Vector3d heightLever(const EstimatorOptions& o, const SystemSetup& setup) {
  return carriedHeightUsed(o, setup) ? Eigen::Vector3d::Zero() : setup.height_p_IH;
}

namespace {

/// The in-motion alignment's options from the estimator's (init.motion_*, the bias priors, the
/// height model), `p_IH` the lever of its vertical sensor.
MotionAlignerOptions alignerOptions(const EstimatorOptions& o, const Eigen::Vector3d& p_IH) {
  MotionAlignerOptions a;
  a.p_IH = p_IH;
  a.window_s = o.init.motion_window_s;
  a.min_span_s = o.init.motion_min_span_s;
  a.min_ranges = o.init.motion_min_ranges;
  a.max_sigma_yaw_deg = o.init.motion_max_sigma_yaw_deg;
  a.max_sigma_p_m = o.init.motion_max_sigma_p_m;
  a.relinearize_rad = o.init.motion_relinearize_rad;
  a.sigma_bias_acc_m_s2 = o.init.sigma_bias_acc_m_s2;
  a.sigma_bias_gyro_rad_s = o.init.sigma_bias_gyro_rad_s;
  a.outlier_m = o.init.range_init_outlier_m;
  a.ambiguity_chi2 = o.init.ambiguity_chi2;
  a.gravity_m_s2 = o.gravity_m_s2;
  a.max_imu_gap_s = o.imu.max_dt_s;
  a.max_window_s = o.init.motion_max_window_s;
  a.height_tilt_correction = o.height.tilt_correction;
  a.sigma_bias_height_m = o.height.init_bias_sigma_m;
  return a;
}

/// The alignment's options; its height model is the baro's (lever p_IP, no tilt correction, bias
/// prior baro.init_bias_sigma_m) when the baro aligns, else the height model's.
MotionAlignerOptions alignerOptionsFor(const EstimatorOptions& o, const SystemSetup& setup) {
  MotionAlignerOptions a =
      alignerOptions(o, baroAligns(o, setup) ? setup.baro_p_IP : heightLever(o, setup));
  if (baroAligns(o, setup)) {
    a.height_tilt_correction = false;
    a.sigma_bias_height_m = o.baro.init_bias_sigma_m;
  }
  if (o.flight_volume.enabled) a.flight_volume = setup.flight_volume;
  a.volume_margin_m = o.flight_volume.candidate_margin_m;
  return a;
}

StillnessDetector stillnessDetector(const EstimatorOptions& o) {
  return StillnessDetector(StillnessOptions{}, o.imu.acc_noise_density, o.imu.gyro_noise_density, o.gravity_m_s2);
}

}  // namespace

Initialization::Initialization(const EstimatorOptions& options, const SystemSetup& setup, Diagnostics& diag,
                               StepTimings& timings)
    : options_(options),
      setup_(setup),
      diag_(diag),
      timings_(timings),
      carried_height_(estimator::carriedHeightUsed(options, setup)),
      baro_aligns_(estimator::baroAligns(options, setup)),
      aligner_(alignerOptionsFor(options, setup), setup.rel_tag_positions),
      still_detector_(stillnessDetector(options)) {
  reset();
}

void Initialization::reset() {
  landed_ = std::make_unique<StaticInitializer>(options_, setup_);
  aligner_.clear();
  aligner_.setGravityAlongPlusZ(false);
  decided_sign_ = 0;
  last_align_try_.reset();
  last_align_height_.reset();
}

void Initialization::forgetStreams() {
  still_at_.clear();
  still_detector_ = stillnessDetector(options_);
  have_flight_state_ = false;
  last_pressure_pa_.reset();
}

void Initialization::addAlignHeight(const AlignHeight& h) {
  // Thinned to height.align_rate_hz: a vertical constraint, not a trajectory.
  if (options_.height.align_rate_hz <= 0.0) return;
  if (last_align_height_ && (h.t - *last_align_height_).sec() < 1.0 / options_.height.align_rate_hz - 1e-6 &&
      h.t >= *last_align_height_)
    return;
  last_align_height_ = h.t;
  aligner_.addHeight(h);
}

void Initialization::feedHeight(const HeightSample& h) {
  if (options_.height.enabled && h.range_m >= options_.height.min_range_m)  // usable readings only
    addAlignHeight({h.t, h.range_m, options_.height.sigma_m});
}

void Initialization::feedBaro(const BaroSample& b) {
  const double ref = *setup_.baro_reference_pressure_pa;
  const double sigma_m = std::abs(atmosphere::dHeightDPressure(b.pressure_pa, ref)) * options_.baro.pressure_sigma_pa;
  addAlignHeight({b.t, atmosphere::heightFromPressure(b.pressure_pa, ref), sigma_m});
}

void Initialization::feedRange(const RangeSample& r, const UwbNetwork& network, const FusionStrategy* filter) {
  SensorId tag = r.id_initiator, anchor = r.id_responder;
  if (!network.isTag(tag)) std::swap(tag, anchor);
  if (!network.isTag(tag) || network.isTag(anchor)) return;
  const Eigen::Vector3d* p = network.exactAnchor(anchor);
  std::optional<Eigen::Vector3d> p_est;
  if (!p && filter && filter->state().values<AnchorKind>().count(anchor))
    p_est = filter->state().values<AnchorKind>().at(anchor).p_AinG;
  if (!p && !p_est && setup_.abs_anchor_positions.count(anchor)) p_est = setup_.abs_anchor_positions.at(anchor);
  if (!p && !p_est) return;
  const PairBias pb = network.pairBias(tag, anchor);
  AlignRange a;
  // The IMU-clock instant the range was measured: its stamp less setup.yaml's delay of the UWB stamps
  // (estimator/uwb/clock_offset_kind.h). Not the filter's estimate of it: the aligner judges the
  // filter, and a delay learnt while the pose was wrong (ISAS-Walk1's first seconds, −158 ms) moved
  // its gravity check and re-alignments (ISAS-Walk1 0.250 → 0.257 m).
  a.t = r.t - Duration::fromSec(network.clockOffsetPrior_s());
  a.tag = tag;
  a.anchor = anchor;
  a.p_AinG = p ? *p : *p_est;
  a.d_m = ((options_.uwb.use_corrected_range ? r.range_corr_m : r.range_m) - pb.gamma_m) / pb.beta;
  a.sigma_m = network.rangeSigma(tag, anchor, r.R_m2);
  aligner_.addRange(a);
}

void Initialization::feed(const EstimatorInput& in, const UwbNetwork& network, const FusionStrategy* filter) {
  if (const auto* s = std::get_if<ImuSample>(&in)) {
    aligner_.addImu(*s);
    if (carried_height_) feedHeight(HeightSample{s->t, setup_.carried_height->height_m});
    // Stillness is the evidence of rest only while no flight state was received.
    if (!have_flight_state_ && options_.zupt.detect_stillness) {
      const bool still = still_detector_.add(*s);
      still_at_[s->t.us] = still;
      if (!filter) landed_->addStillness(still);
    }
  } else if (std::holds_alternative<FlightStateSample>(in)) {
    have_flight_state_ = true;
  } else if (const auto* b = std::get_if<BaroSample>(&in)) {
    last_pressure_pa_ = b->pressure_pa;
    if (baro_aligns_) feedBaro(*b);
  } else if (const auto* h = std::get_if<HeightSample>(&in)) {
    if (!carried_height_ && !baro_aligns_) feedHeight(*h);
  } else if (const auto* r = std::get_if<RangeSample>(&in)) {
    feedRange(*r, network, filter);
  }
  // A fleet's peer ranges (PeerRange) do not align: the peer's estimate is not an anchor the
  // alignment can judge (MILUV: a peer 2 m off made a vehicle start 5 m off; docs/fleet.md).
}

void Initialization::pruneStillness(int64_t oldest_us) {
  while (!still_at_.empty() && still_at_.begin()->first < oldest_us) still_at_.erase(still_at_.begin());
}

std::optional<InitialBelief> Initialization::tryInitialize(const EstimatorInput& in, bool landed) {
  std::visit(
      [&](const auto& m) {
        using T = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<T, ImuSample>) landed_->addImu(m);
        if constexpr (std::is_same_v<T, BaroSample>) landed_->addBaro(m);
        if constexpr (std::is_same_v<T, RangeSample>) landed_->addRange(m);
        if constexpr (std::is_same_v<T, FlightStateSample>) landed_->addFlightState(m);
      },
      in);
  if (!std::holds_alternative<ImuSample>(in)) return std::nullopt;
  if (auto belief = landed_->tryInitialize()) return belief;
  // At rest the landed data decides; in motion (or when it cannot fix the pose) the aligner.
  if (landed_->isStatic() && landed_->waitingFor().rfind("motion", 0) != 0) return std::nullopt;
  const Timestamp t = inputTime(in);
  if (last_align_try_ && (t - *last_align_try_).sec() < kAlignRetry_s) return std::nullopt;
  last_align_try_ = t;
  const int relinearized_before = aligner_.relinearizations();
  compareGravitySigns(t);
  const auto r = align(Eigen::Vector3d::Zero());
  if (aligner_.relinearizations() > relinearized_before) diag_.count("init_motion_relinearized");
  if (!r) {
    // Why, with its figures (the first few of a run; all are counted): a user whose recording
    // never initializes sees what the data lacks (ambiguous rival pose, heading, too few ranges).
    diag_.report("init_motion_refused", "estimator: in-motion alignment at t=" + formatSeconds(t) +
                                            " refused: " + aligner_.reason());
    return std::nullopt;
  }
  InitialBelief b = beliefFrom(*r, landedAt(r->t, landed));
  b.gravity_z_sign = decided_sign_;
  return b;
}

void Initialization::compareGravitySigns(Timestamp t) {
  // Baro and heights measure along −z of G: with them the frame is taken as it is. After a reset
  // the node compares again (its sign went back to −z with the aligner's).
  if (decided_sign_ != 0 || sawVerticalSensor()) return;
  const auto check = aligner_.checkGravityDirection(Eigen::Vector3d::Zero());
  if (!check) return;  // too little data to compare yet (the aligner says why when it refuses)
  if (!check->zDown() && !check->zUp()) {
    diag_.count("gravity_compare_undecided");  // the next try compares again
    return;
  }
  decided_sign_ = check->zDown() ? 1 : -1;
  const std::string costs = fmt::format("cost {:.1f} with gravity along -z, {:.1f} along +z, margin {:.1f}, {} ranges",
                                        check->cost_z_up, check->cost_z_down, check->margin, check->n_ranges);
  if (decided_sign_ < 0) {
    spdlog::info("estimator: gravity along -z of G as assumed, by the alignment window at t={} ({})", formatSeconds(t),
                 costs);
    return;
  }
  aligner_.setGravityAlongPlusZ(true);
  spdlog::warn("estimator: at t={} the alignment window fits the IMU with the anchors' frame G upside down ({}): its "
               "z axis points down; gravity is taken along +z of G (docs/real_data.md)",
               formatSeconds(t), costs);
}

std::optional<AlignmentResult> Initialization::align(const Eigen::Vector3d& bias_gyro_rad_s,
                                                     const std::optional<MotionAligner::HeadingPrior>& heading) {
  ScopedStepTimer timer(timings_, "align");
  return aligner_.solve(bias_gyro_rad_s, heading);
}

bool Initialization::landedAt(Timestamp t, bool current) const {
  if (have_flight_state_) return current;
  // Neither a flight state nor the IMU's stillness: no evidence of rest, so not landed (else the
  // node's flag, which starts landed, would stay so the whole flight and ZUPT it), unless the user
  // says a vehicle without a flight state rests (init.assume_landed_without_flight_state).
  if (!options_.zupt.detect_stillness) return options_.init.assume_landed_without_flight_state;
  auto it = still_at_.find(t.us);
  return it != still_at_.end() && it->second;
}

InitialBelief Initialization::beliefFrom(const AlignmentResult& r, bool landed) const {
  InitialBelief b;
  b.t = r.t;
  b.imu = r.imu;
  b.cov = r.cov;
  b.from_ranges = true;
  b.n_ranges_used = r.n_ranges;
  b.range_fit_rms_m = r.rms_m;
  b.last_imu = r.last_imu;
  b.landed = landed;
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
    b.baro_bias_var_m2 = r.cov(ImuErr::kP + 2, ImuErr::kP + 2) + kBaroReferenceReadingVar_m2;
  }
  return b;
}

std::string Initialization::waitingFor() const {
  return landed_->waitingFor() + (aligner_.reason().empty() ? "" : "; " + aligner_.reason());
}

}  // namespace meshnav::estimator
