/// @file estimator_node.cpp
/// @brief EstimatorNode, first part: input validation and ordering, processing, the IMU step,
/// commands and the outputs (pose, anchors, status). The measurement updates (baro, height, range,
/// anchor initialization) are in estimator_node_updates.cpp; initialization, health and recovery
/// in estimator_node_robustness.cpp.

#include "estimator/node/estimator_node.h"
#include "common/plausibility.h"

#include <spdlog/spdlog.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <iterator>
#include <chrono>
#include <cmath>

#include "common/anchor_init_io.h"
#include "estimator/filter/strategy_factory.h"
#include "estimator/node/node_internals.h"
#include "estimator/uwb/anchor_layout.h"

namespace meshnav::estimator {

using node_internal::where;

std::vector<EstimatorInput> mergeInTimeOrder(const Dataset& ds) {
  std::vector<EstimatorInput> all;
  forEachInputKind([&]<class T>() {
    if constexpr (requires { InputKind<T>::kDataset; })
      for (const auto& s : ds.*InputKind<T>::kDataset) all.emplace_back(s);
  });
  std::stable_sort(all.begin(), all.end(),
                   [](const EstimatorInput& a, const EstimatorInput& b) { return inputOrder(a) < inputOrder(b); });
  return all;
}

using node_internal::weakestPositionAxis;

namespace {

/// The options with the setup's noise figures, and for a carried rig (setup `carried_height`) the
/// height model turned into the carried-height pseudo-sensor: reading σ, the bias's prior σ from
/// the setup and its random walk, no tilt correction and no minimum range.
EstimatorOptions withSetup(EstimatorOptions o, const SystemSetup& setup) {
  o.applySetupNoise(setup.noise);
  if (carriedHeightUsed(o, setup)) {
    o.height.enabled = true;
    o.height.sigma_m = o.carried_height.sigma_m;
    o.height.bias_rw_m_per_sqrt_s = o.carried_height.bias_rw_m_per_sqrt_s;
    o.height.init_bias_sigma_m = setup.carried_height->sigma_m;
    o.height.tilt_correction = false;
    o.height.min_range_m = 0.0;
  }
  return o;
}

}  // namespace

EstimatorNode::EstimatorNode(const EstimatorOptions& options, const SystemSetup& setup, EstimatorSinks sinks)
    : EstimatorNode(options, setup, std::move(sinks), Quiet{}) {
  reportSetupGeometry();
}

EstimatorNode::EstimatorNode(const EstimatorOptions& options, const SystemSetup& setup, EstimatorSinks sinks, Quiet)
    : options_(withSetup(options, setup)),
      setup_(setup),
      sinks_(std::move(sinks)),
      gate_(options_, diag_),
      imu_units_(ImuUnitsCheck::Options{.gravity_m_s2 = options_.gravity_m_s2}),
      init_(options_, setup_, diag_, timings_),
      settler_(options_.init.settle_max_s, !setup_.rel_tag_positions.empty()),
      gravity_(options_.init.motion_min_span_s, options_.init.motion_window_s,
               options_.init.gravity_early_check_nis_ratio, diag_),
      volume_(options_.flight_volume, setup_, diag_),
      outputs_(options_.pose_output_rate_hz, options_.anchors_output_rate_hz, options_.status_rate_hz),
      sensors_{BaroUpdater(options_.baro, setup.baro_id, setup.baro_p_IP),
               HeightUpdater(options_.height, setup.height_id, heightLever(options_, setup),
                             carriedHeightUsed(options_, setup)),
               RangeUpdater(options_.uwb, options_.strategy == "dah"),
               AnchorJoin(options_.uwb, options_.strategy == "dah", setup_, diag_), ImuPropagation(options_.imu),
               ZuptModel(Eigen::Vector3d(0.0, 0.0, -options.gravity_m_s2))},
      health_(options_.health),
      recovery_(options_.recovery, options_.init.motion_window_s),
      recovery_confirmation_(options_.health),
      reentry_(options_.uwb, diag_),
      resume_(options_, setup_, diag_),
      timeline_(options_.window_s, options_.refine, AnchorRerun::enabledBy(options_), diag_),
      rerun_(options_, diag_, timings_),
      smoother_(options_.fixed_lag, diag_, sinks_.pose_smoothed) {
  options_.validate();
  resetAll();
}

void EstimatorNode::reportSetupGeometry() {
  const auto layout = AnchorLayout::of(setup_.abs_anchor_positions);
  if (!layout || !layout->nearlyCollinear()) return;
  // Anchors in a wall of the flight volume: the mirror image behind the wall is told apart.
  if (volume_.plane() && std::abs(volume_.plane()->normal().dot(layout->acrossLine_G())) > 0.9) return;
  diag_.report("known_anchors_nearly_collinear", "estimator: " + layout->describe());
}

void EstimatorNode::resetAll() {
  flushSmoothed();  // the smoothed poses still waiting go out (a Reset, a clock gone back): one per POSE
  smoother_.reset();
  init_.reset();
  settler_.clear();
  volume_.reset();
  gravity_.reset();
  recovery_.reset();
  recovery_confirmation_.reset();
  sensors_.zupt = ZuptModel(gravityG());
  cur_ = FilterContext{};
  cur_.noise_adapter = ProcessNoiseAdapter(options_.process_noise);
  cur_.range_errors = RangeErrorCorrelation(options_.uwb.range_error_correlation_s);
  cur_.network = std::make_shared<const UwbNetwork>(setup_, options_.uwb.sigma_range_m,
                                                    options_.uwb.uncalibratedPairSigma());
  rerun_.abandon();  // its base is gone
  timeline_.clear();
  rerun_.reset();
  reentry_.reset();
  sensors_.height.setBiasPrior(std::nullopt);
  gate_.forgetKeys();
  sensors_.baro.setReference(std::nullopt);
  instance_stats_.clear();
  range_fates_.clear();
  outputs_.resetPose();
  held_for_imu_.clear();
  next_imu_.reset();
  pending_next_imu_.reset();
}

void EstimatorNode::event(bool first, const std::string& kind, const std::string& message) {
  if (!first) return;
  if (message.empty())
    diag_.count(kind);
  else
    diag_.report(kind, message);
}

void EstimatorNode::onInput(const EstimatorInput& in_raw) {
  if (!gate_.valid(in_raw)) return;
  EstimatorInput in = in_raw;
  switch (gate_.admitTime(in)) {
    case InputGate::Verdict::kRefused: return;
    case InputGate::Verdict::kClockBack: startOverAfterClockBack(); break;
    case InputGate::Verdict::kAdmitted: break;
  }
  if (!gate_.admitOnce(in_raw, timeline_.newest())) return;
  // Commands are not measurements: they apply now (at the newest time) unless they are newer.
  const std::optional<Timestamp>& newest = timeline_.newest();
  if (newest && (std::holds_alternative<AnchorInit>(in) || std::holds_alternative<EstimatorCommand>(in))) {
    if (auto* a = std::get_if<AnchorInit>(&in)) a->t = std::max(a->t, *newest);
    if (auto* c = std::get_if<EstimatorCommand>(&in)) c->t = std::max(c->t, *newest);
  }
  if (const auto* c = std::get_if<EstimatorCommand>(&in); c && c->action == EstimatorCommand::Action::Reset) {
    spdlog::info("estimator: reset by command at t={}", formatSeconds(c->t));
    diag_.count("reset");
    resetAll();
    imu_units_.reset();  // a new stream
    return;
  }
  // An IMU in other units than m/s² and rad/s: no estimate, the reason in the status.
  if (const auto* s = std::get_if<ImuSample>(&in)) {
    if (const std::string fault = imu_units_.add(*s); !fault.empty()) {
      spdlog::error("estimator: {}: {}; the estimator stops (docs/faults.md)", where("IMU", s->t), fault);
      diag_.count("imu_units_implausible");
      resetAll();
    }
  }
  if (!imu_units_.fault().empty()) return;
  // A restart's checkpoint (offered until the first IMU sample decides) resumes the pose at once:
  // nothing waits for it.
  if (!initialized() && !resume_.offered()) {
    settle(in);
    return;
  }
  route(in);
}

void EstimatorNode::settle(const EstimatorInput& in) {
  // ANCHOR_INIT and commands are not data of a window: they apply at once, as after the
  // initialization (held, a command stamped an hour ahead would move the clock past every input).
  if (std::holds_alternative<AnchorInit>(in) || std::holds_alternative<EstimatorCommand>(in)) {
    route(in);
    return;
  }
  if (!settler_.add(in)) {
    // A flight state or a peer range is taken as it comes; a stream's input is reported.
    if (InputSettler::isStreamInput(in))
      diag_.report("late_for_initialization",
                 where("input", inputTime(in)) + " (" + inputKindName(in) +
                     ") came after later inputs had gone to the initialization: processed out of order");
    route(in);
  }
  // Settled inputs in the canonical order; once one of them initializes the filter, the rest
  // (settled or not) go on the usual path, which handles later arrivals by rewinding.
  for (const EstimatorInput& s : settler_.takeSettled()) route(s);
  if (initialized())
    for (const EstimatorInput& s : settler_.takeAll()) route(s);
}

void EstimatorNode::route(const EstimatorInput& in) {
  // A measurement between two IMU samples waits for the second (heldForNextImu); an IMU sample
  // releases the ones before it, with itself as their next sample.
  if (holdForNextImu(in)) return;
  if (const auto* s = std::get_if<ImuSample>(&in)) {
    releaseHeld(*s, false);  // those before it, with it as their next sample
    accept(in);
    releaseHeld(*s, true);  // those at its time come after it in the canonical order
    return;
  }
  if (!held_for_imu_.empty() && cur_.last_imu &&
      inputTime(in) > cur_.last_imu->t + Duration::fromSec(options_.imu.max_dt_s))
    releaseHeld(std::nullopt, true);  // the IMU is in a gap: they are propagated on the gap's readings
  accept(in);
}

bool EstimatorNode::holdForNextImu(const EstimatorInput& in) {
  // Past imu.max_dt_s after the last sample the IMU is in a gap: no sample is due.
  if (!options_.imu.hold_for_next_sample || !initialized() || !cur_.last_imu || !isMeasurement(in) ||
      inputTime(in) <= cur_.last_imu->t || inputTime(in) > cur_.last_imu->t + Duration::fromSec(options_.imu.max_dt_s))
    return false;
  held_for_imu_.push_back(in);
  return true;
}

void EstimatorNode::releaseHeld(const std::optional<ImuSample>& next, bool at_its_time) {
  if (held_for_imu_.empty()) return;
  std::deque<EstimatorInput> held;
  held.swap(held_for_imu_);
  // In the canonical order, as they would have come in order (arrival may have swapped two).
  std::stable_sort(held.begin(), held.end(),
                   [](const EstimatorInput& a, const EstimatorInput& b) { return inputOrder(a) < inputOrder(b); });
  for (const EstimatorInput& h : held) {
    if (next && (inputTime(h) > next->t || (inputTime(h) == next->t) != at_its_time)) {
      held_for_imu_.push_back(h);  // not released by this call: it waits
      continue;
    }
    // At the sample's own time the sample is the last one: nothing to interpolate towards.
    pending_next_imu_ = at_its_time ? std::nullopt : next;
    accept(h);
    pending_next_imu_.reset();
  }
}

void EstimatorNode::flushHeld() {
  for (const EstimatorInput& s : settler_.takeAll()) route(s);  // the stream's end: nothing more will settle them
  releaseHeld(std::nullopt, true);
}

std::optional<ImuSample> EstimatorNode::orReleasingSample(const EstimatorInput& in,
                                                          std::optional<ImuSample> next) const {
  if (next || !pending_next_imu_ || !isMeasurement(in)) return next;
  // Nothing stored after `in` up to imu.max_dt_s: the sample being released, when it is after `in`.
  const Timestamp t = inputTime(in);
  if (pending_next_imu_->t >= t && pending_next_imu_->t <= t + Duration::fromSec(options_.imu.max_dt_s))
    return pending_next_imu_;
  return std::nullopt;
}

void EstimatorNode::accept(const EstimatorInput& in) {
  const Timestamp t = inputTime(in);
  const std::optional<Timestamp>& newest = timeline_.newest();
  init_.feed(in, *cur_.network, cur_.filter.get());
  if (std::holds_alternative<ImuSample>(in)) init_.pruneStillness(timeline_.oldestReplayUs(t.us));
  if (!initialized()) {
    // Only measurements drive the clock: a command stamped far ahead before the first measurement
    // would otherwise leave every later measurement too old.
    if (!std::holds_alternative<AnchorInit>(in) && !std::holds_alternative<EstimatorCommand>(in))
      timeline_.advance(t);
    if (const auto* s = std::get_if<ImuSample>(&in); s && resume_.offered()) {
      if (auto b = resume_.at(*s, sensors_.anchor_join.held())) {
        initialize(*b);
        publishPeriodic();
        return;
      }
    }
    feedInitializer(in);
    publishPeriodic();
    return;
  }
  if (std::holds_alternative<ImuSample>(in)) runGravityDirection(t);
  if (t < timeline_.start()) {
    diag_.count("before_init");
    return;
  }
  if (timeline_.beforeWindow(t)) {
    diag_.report("rejected_too_old", where("input", t) + " is older than the newest " + formatSeconds(*newest) +
                                         " minus the window " + std::to_string(options_.window_s) + " s");
    return;
  }
  rerun_.poll(false, timeline_, *this);  // a worker re-run that is done comes in before this input
  InputTimeline::Entry e{inputOrder(in), in, nullptr};
  auto& window = timeline_.window();
  auto pos = timeline_.placeOf(e.key);
  if (pos == window.end()) {
    e.before = std::make_shared<const FilterContext>(cur_.copy());
    window.push_back(std::move(e));
    next_imu_ = nextImuInWindow(std::prev(window.end()));
    process(window.back().input, true);
    next_imu_.reset();
  } else {
    // Out of sequence: rewind to the snapshot before its place, re-process in order.
    diag_.count("out_of_sequence");
    rerun_.noteInserted(e.key);
    ScopedStepTimer rewind_timer(timings_, "rewind");
    cur_ = pos->before->copy();
    e.before = pos->before;
    auto it = window.insert(pos, std::move(e));
    next_imu_ = nextImuInWindow(it);
    process(it->input, true);
    replayAfter(it);  // resets next_imu_
  }
  timeline_.advance(t);
  if (smoother_.enabled()) {
    ScopedStepTimer timer(timings_, "fixed_lag");
    smoother_.work();  // after this input's POSE: a pass never delays one
  }
  releaseReentryIfDue();
  // Anchors calibrated together arrive as consecutive ANCHOR_INITs: one re-run for all of them.
  // Not from a measurement being released: the re-run would end with it but without its sample.
  if (rerun_.pending() && !rerun_.running() && !std::holds_alternative<AnchorInit>(in) && !pending_next_imu_)
    startRerun();
  timeline_.retire(*newest - Duration::fromSec(options_.window_s));
  const int64_t oldest_us = (*newest - Duration::fromSec(options_.window_s)).us;
  while (!range_fates_.empty() && range_fates_.begin()->first.t_us < oldest_us) range_fates_.erase(range_fates_.begin());
  init_.pruneStillness(timeline_.oldestReplayUs(newest->us));
  updateHealth(*newest);
  publishPeriodic();
}

void EstimatorNode::replayAfter(InputTimeline::Window::iterator it) {
  for (++it; it != timeline_.window().end(); ++it) {
    it->before = std::make_shared<const FilterContext>(cur_.copy());
    next_imu_ = nextImuInWindow(it);
    process(it->input, false);
  }
  next_imu_.reset();
}

std::optional<ImuSample> EstimatorNode::nextImuInWindow(InputTimeline::Window::iterator it) const {
  if (!options_.imu.hold_for_next_sample) return std::nullopt;  // first processing extrapolated: so do replays
  const InputTimeline::Window& w = timeline_.window();
  const size_t i = static_cast<size_t>(it - timeline_.window().begin());
  // After the stored inputs comes the sample being released (releaseHeld), if any.
  return orReleasingSample(it->input, nextImuSample(i, w.size(), [&](size_t j) -> const EstimatorInput& {
    return w[j].input;
  }, options_.imu.max_dt_s));
}

void EstimatorNode::process(const EstimatorInput& in, bool first) {
  std::visit(
      [&](const auto& m) {
        using T = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<T, ImuSample>) processImu(m, first);
        if constexpr (std::is_same_v<T, BaroSample>) processBaro(m, first);
        if constexpr (std::is_same_v<T, RangeSample>) processRange(m, first);
        if constexpr (std::is_same_v<T, PeerRange>) processPeerRange(m, first);
        if constexpr (std::is_same_v<T, HeightSample>) {
          if (init_.carriedHeight())
            event(first, "height_ignored_carried_height");  // the carried height uses the height instance
          else
            processHeight(m, first);
        }
        if constexpr (std::is_same_v<T, FlightStateSample>) cur_.landed = m.landed;
        if constexpr (std::is_same_v<T, AnchorInit>) {
          if (!rerun_.skipReplayed(m, first, *cur_.filter)) applyAnchorInit(m, first);
          rerun_.noteJoin(m, first, *cur_.filter);
        }
        if constexpr (std::is_same_v<T, EstimatorCommand>) applyCommand(m, first);
      },
      in);
}

void EstimatorNode::propagateTo(Timestamp t) {
  if (!cur_.last_imu || t <= cur_.filter->state().t) return;
  ScopedStepTimer timer(timings_, "propagate");
  propagateRecorded([&] { sensors_.imu.toTime(*cur_.filter, t, propagationInputs()); });
}

namespace {
/// The filter's IMU block as the fixed-lag smoother keeps it.
ImuBelief imuBeliefOf(const FusionStrategy& f) {
  const NominalState& x = f.state();
  return ImuBelief{x.t, x.imu, ImuMatrix(f.covariance(x.imu_id, x.imu_id))};
}
}  // namespace

template <class Propagate>
void EstimatorNode::propagateRecorded(Propagate&& propagate) {
  FusionStrategy& f = *cur_.filter;
  if (!smoother_.wants(f.state().t)) {  // off, or a replay of what no smoothed pose needs
    if (smoother_.enabled()) smoother_.skip(f.state().t);
    propagate();
    return;
  }
  ImuBelief from;
  {
    ScopedStepTimer timer(timings_, "fixed_lag");
    from = imuBeliefOf(f);
    f.startTransition();
  }
  propagate();
  ScopedStepTimer timer(timings_, "fixed_lag");
  smoother_.onPropagation(from, imuBeliefOf(f), f.takeTransition());
}

void EstimatorNode::flushSmoothed() {
  if (smoother_.enabled() && initialized()) smoother_.finish(imuBeliefOf(*cur_.filter));
}

ImuPropagation::Inputs EstimatorNode::propagationInputs() const {
  return {cur_.last_imu, cur_.prev_imu, cur_.mean_reading, gravityG(), cur_.noise_adapter.scale(),
          next_imu_ ? &*next_imu_ : nullptr};
}

void EstimatorNode::processImu(const ImuSample& s, bool first) {
  FusionStrategy& f = *cur_.filter;
  const Timestamp t0 = f.state().t;
  // Gaps on the IMU's own time line (range and baro updates move the filter's time meanwhile).
  if (const double gap_s = cur_.last_imu ? (s.t - cur_.last_imu->t).sec() : 0.0; gap_s > options_.imu.max_dt_s) {
    event(first, "imu_gap",
          where("IMU", s.t) + ": no IMU sample for " + std::to_string(gap_s) + " s; propagated on " +
              options_.imu.gap_readings + " readings with inflated noise");
    recovery_.noteImuGap(s.t, gap_s);
  }
  if (s.t > t0) {
    ScopedStepTimer timer(timings_, "propagate");
    propagateRecorded([&] { sensors_.imu.toSample(f, s, propagationInputs()); });
  }
  const std::optional<ImuSample> previous = cur_.last_imu;
  cur_.prev_imu = previous;
  cur_.last_imu = s;
  sensors_.imu.updateMean(cur_.mean_reading, cur_.filter->state().imu, s, previous, gravityG());
  if (!init_.haveFlightState()) cur_.landed = init_.landedAt(s.t, cur_.landed);
  if (cur_.landed && previous && s.t > previous->t)
    cur_.rest_rate.add(s.gyro_rad_s, (s.t - previous->t).sec(), options_.imu.max_dt_s);
  else if (!cur_.landed)
    cur_.rest_rate.reset();
  if (options_.zupt.enabled && cur_.landed && (s.t - cur_.last_zupt).sec() >= 1.0 / options_.zupt.rate_hz - 1e-9)
    processZupt(s, first);
  if (init_.carriedHeight() &&
      (s.t - cur_.last_carried_height).sec() >= 1.0 / options_.carried_height.rate_hz - 1e-9) {
    cur_.last_carried_height = s.t;
    processHeight(HeightSample{s.t, setup_.carried_height->height_m}, first);
  }
  if (first && (sinks_.pose || smoother_.enabled()) && outputs_.poseDue(s.t)) {
    const PoseEstimate e = poseOf(*cur_.filter);
    if (sinks_.pose) sinks_.pose(e);
    smoother_.onPose(e);
  }
}

void EstimatorNode::applyCommand(const EstimatorCommand& c, bool first) {
  switch (c.action) {
    case EstimatorCommand::Action::AddAnchor:
      applyAnchorInit(c.anchorToAdd(), first);
      break;
    case EstimatorCommand::Action::RemoveInstance: {
      if (c.id == setup_.imu_id || c.id == setup_.baro_id) {
        event(first, "bad_command", "ESTIMATOR_CMD: cannot remove the IMU or baro instance " + std::to_string(c.id));
        break;
      }
      bool removed = cur_.filter->removeInstance(c.id);
      if (first) rerun_.forget(c.id);
      if (cur_.network->isTag(c.id) || cur_.network->exactAnchor(c.id) || cur_.network->isCalibrated(c.id)) {
        auto net = std::make_shared<UwbNetwork>(*cur_.network);
        removed = net->removeDevice(c.id) || removed;
        net->setCalibrated(c.id, false);
        cur_.network = std::move(net);
      }
      if (!removed) event(first, "bad_command", "ESTIMATOR_CMD: no instance " + std::to_string(c.id) + " to remove");
      break;
    }
    case EstimatorCommand::Action::Reset: break;  // handled in onInput
  }
}

std::optional<PoseEstimate> EstimatorNode::pose() const {
  if (!initialized()) return std::nullopt;
  return poseOf(*cur_.filter);
}

std::vector<AnchorEstimate> EstimatorNode::anchors() const {
  if (!initialized()) return {};
  return anchorsOf(*cur_.filter, *cur_.network);
}

EstimatorStatus EstimatorNode::status() const {
  EstimatorStatus s;
  s.t = timeline_.newest().value_or(Timestamp{});
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
  s.uwb_clock_offset_s = setup_.uwb_clock.offset_s;  // setup's constant, or the state's estimate below
  if (initialized()) {
    const Eigen::MatrixXd P = cur_.filter->covariance(setup_.imu_id, setup_.imu_id);
    const auto [sigma_p, axis] = weakestPositionAxis(P.block<3, 3>(ImuErr::kP, ImuErr::kP));
    s.sigma_p_max_m = sigma_p;
    s.weak_axis_G = axis;
    s.sigma_yaw_deg =
        std::sqrt(so3::yawVariance(cur_.filter->state().imu.q_ItoG, P.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta))) *
        180.0 / M_PI;
    for (const auto& [id, delay_s] : cur_.filter->state().values<ClockOffsetKind>()) {
      s.uwb_clock_offset_s = delay_s;
      s.uwb_clock_offset_sigma_s = std::sqrt(cur_.filter->covariance(id, id)(0, 0));
    }
  }
  return s;
}

void EstimatorNode::publishPeriodic() {
  if (!timeline_.newest()) return;
  const Timestamp now = *timeline_.newest();
  if (initialized() && sinks_.anchors && outputs_.anchorsDue(now)) sinks_.anchors(anchors());
  if (sinks_.status && outputs_.statusDue(now)) sinks_.status(status());
}

}  // namespace meshnav::estimator