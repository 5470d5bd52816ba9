#pragma once
/// @file estimator_node.h
/// @brief The estimator node (instance handler, docs/modular_estimator.md), free of LCM: consumes IMU, baro,
/// range, flight state, ANCHOR_INIT, ESTIMATOR_CMD and HEIGHT (downward rangefinder) inputs, publishes POSE, ANCHORS and
/// ESTIMATOR_STATUS through callbacks.
///
/// - Before initialization, inputs feed the `StaticInitializer` (no propagation).
/// - Afterwards every input is kept in a time-sorted history over a sliding window with the
///   filter snapshot before it. An input older than the newest processed one rewinds to the
///   snapshot before its place and re-processes the rest in the canonical order
///   (estimator_input.h), so the result equals in-order processing. Older than the window:
///   rejected ("rejected_too_old"). Bad values: "bad_input". Unknown range ids: "unknown_id".
/// - Time stamps far from the node's current time (`time.max_offset_s`) are refused before all
///   of this and counted per input kind ("IMU:time_ahead", "RANGE:time_behind", ...), so they never
///   move the filter's clock; a jump of the whole stream is taken after `time.rebase_after`
///   agreeing inputs ("time_rebased"; backwards: the node starts over). ANCHOR_INIT and
///   ESTIMATOR_CMD stamped that far apply at the current time ("<KIND>:time_clamped").
///   estimator_node_time.cpp, common/time_guard.h.
///   A snapshot is `FusionStrategy::clone()`: for dp/dah O(#instances) pointer copies
///   (copy-on-write instances), so the history is also each instance's belief/factor history.
///   Step timings include "rewind" (restore + re-processing of one late input).
/// - An input that comes a second time (same kind, time and ids: a network that duplicates
///   datagrams, a sender that retransmits) is dropped and counted ("RANGE:duplicate", ...), so a
///   range is never fused twice; keys are kept over the out-of-sequence window.
/// - IMU samples propagate (inputs interpolated to the middle of the step); baro, height and range
///   updates propagate to their own time with the readings extrapolated along the last two
///   samples (propagateTo), or, with `imu.hold_for_next_sample` (off by default), interpolated
///   towards the IMU sample after them, for which a measurement past the last sample waits
///   (holdForNextImu; not through a gap of `imu.max_dt_s`, nor past the stream's end: flushHeld).
///   While landed a
///   zero-velocity update runs at `zupt.rate_hz` with the latest IMU reading.
/// - ANCHOR_INIT and ESTIMATOR_CMD apply at max(their time, newest time).
/// - Re-run on an anchor join (AnchorRerun, estimator/refine/anchor_rerun.h): inputs that leave the
///   window are archived up to `refine.max_history_s`; after a live ANCHOR_INIT the node restores
///   the oldest stored state, adds the calibrated anchors there with a loose prior and
///   re-processes every stored input ("rerun", "rerun_inputs"; centralized and dp by default).
///   With `refine.rerun_mode` async (the LCM process) the re-run is computed on a worker thread
///   from immutable copies while the node keeps processing and publishing; its result is swapped
///   in at the first input after the worker is done and the inputs that came meanwhile are
///   re-processed from it. The stored inputs and their contexts: InputTimeline, FilterContext.
/// - Initialization: while at rest (flight state, else IMU stillness) from the landed data
///   (StaticInitializer); in motion, or when the landed data cannot fix the pose (one tag,
///   coplanar anchors), from ranges and strapdown increments over a window (MotionAligner).
/// - IMU gaps are detected on the IMU's own time line; beyond `imu.max_dt_s` the filter runs on
///   held readings with inflated process noise ("imu_gap").
/// - Health (HealthMonitor): windowed gating and NIS; `lost` triggers a re-initialization of the
///   IMU instance from the MotionAligner that keeps anchors, baro and tag bias states
///   ("recovery"); see docs/robustness.md.
/// Poses are published per in-order IMU step (decimated to `pose_output_rate_hz`), anchors
/// and status at their rates in data time. Not thread-safe: call from one thread (the re-run
/// worker owns its own copies and never touches the node).

#include <atomic>
#include <chrono>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <vector>

#include "common/diagnostics.h"
#include "common/messages.h"
#include "common/setup.h"
#include "common/types.h"
#include "estimator/baro/baro_updater.h"
#include "estimator/height/height_updater.h"
#include "estimator/core/estimator_options.h"
#include "estimator/filter/fusion_strategy.h"
#include "estimator/refine/anchor_rerun.h"
#include "estimator/restart/resume.h"
#include "estimator/smooth/fixed_lag_smoother.h"
#include "estimator/node/estimator_input.h"
#include "estimator/health/health_monitor.h"
#include "estimator/health/recovery_confirmation.h"
#include "estimator/health/recovery_policy.h"
#include "estimator/imu/imu_propagation.h"
#include "estimator/imu/imu_readings.h"
#include "estimator/imu/imu_units_check.h"
#include "estimator/imu/process_noise_adapter.h"
#include "estimator/health/flight_volume_guard.h"
#include "estimator/init/gravity_direction.h"
#include "estimator/init/initialization.h"
#include "estimator/node/filter_context.h"
#include "estimator/node/input_gate.h"
#include "estimator/node/input_settler.h"
#include "estimator/node/input_timeline.h"
#include "estimator/node/output_schedule.h"
#include "estimator/zupt/rest_rate_mean.h"
#include "estimator/node/step_timings.h"
#include "estimator/uwb/anchor_join.h"
#include "estimator/uwb/range_updater.h"
#include "estimator/uwb/reentry_gate.h"
#include "estimator/uwb/uwb_network.h"
#include "estimator/zupt/zupt_model.h"

namespace meshnav::estimator {

struct EstimatorSinks {
  std::function<void(const PoseEstimate&)> pose;
  /// Fixed-lag smoothed poses (FixedLagSmoother, `fixed_lag.*`): one per POSE, `fixed_lag.lag_s`
  /// to lag_s + period_s of data time after it, in time order. Without this sink nothing is smoothed.
  std::function<void(const PoseEstimate&)> pose_smoothed;
  std::function<void(const std::vector<AnchorEstimate>&)> anchors;
  std::function<void(const EstimatorStatus&)> status;
};

class EstimatorNode : private RerunReplayer {
 public:
  /// Throws std::invalid_argument for invalid options or a strategy not implemented yet. Reports
  /// what the setup leaves weak (reportSetupGeometry), once.
  EstimatorNode(const EstimatorOptions& options, const SystemSetup& setup, EstimatorSinks sinks = {});
  ~EstimatorNode() override;
  EstimatorNode(const EstimatorNode&) = delete;
  EstimatorNode& operator=(const EstimatorNode&) = delete;

  void onImu(const ImuSample& s) { onInput(s); }
  void onBaro(const BaroSample& s) { onInput(s); }
  void onRange(const RangeSample& s) { onInput(s); }
  void onHeight(const HeightSample& s) { onInput(s); }
  void onFlightState(const FlightStateSample& s) { onInput(s); }
  void onAnchorInit(const AnchorInit& a) { onInput(a); }
  void onCommand(const EstimatorCommand& c) { onInput(c); }
  void onInput(const EstimatorInput& in);
  /// Processes the measurements held for their next IMU sample on extrapolated readings: the end
  /// of a stream, when no sample will come (meshnav_run and the process call it at their end).
  void flushHeld();
  /// The end of a stream: every fixed-lag smoothed pose still waiting for its lag goes out,
  /// smoothed with the data there is (meshnav_run and the process call it at their end, after
  /// flushHeld and finishRerun).
  void flushSmoothed();

  bool initialized() const { return filter() != nullptr; }
  /// The current estimate (at the newest processed input), when initialized.
  std::optional<PoseEstimate> pose() const;
  /// Every anchor the node knows: estimated ones with covariance, exact ones with zero covariance.
  std::vector<AnchorEstimate> anchors() const;
  EstimatorStatus status() const;
  const Diagnostics& diagnostics() const { return diag_; }
  const StepTimings& timings() const { return timings_; }
  const EstimatorOptions& options() const { return options_; }
  /// The filter (null before initialization).
  const FusionStrategy* filter() const { return cur_.filter.get(); }
  /// Inputs currently held for out-of-sequence handling.
  size_t historySize() const { return timeline_.window().size(); }
  /// Variance scale of the IMU white noise (ProcessNoiseAdapter), 1 when the densities fit.
  double processNoiseScale() const { return cur_.noise_adapter.scale(); }
  Health health() const { return initialized() ? health_.health() : Health::Initializing; }
  const HealthMonitor& healthMonitor() const { return health_; }
  /// The time of the last re-initialization while it is not yet confirmed by the ranges after it
  /// (RecoveryConfirmation), with how long health has been ok since [s]; nullopt when confirmed.
  std::optional<std::pair<Timestamp, double>> unconfirmedRecovery() const;
  /// Why the node is not initialized yet (empty once it is).
  std::string waitingFor() const;
  /// The state to persist for a restart (initialized only): IMU state and covariance, baro
  /// reference and bias, and (`with_anchors`) the estimated anchors with their marginal covariance
  /// and pair biases (makeCheckpoint).
  EstimatorCheckpoint checkpoint(bool with_anchors = true) const;
  /// The ids of the anchors the filter estimates (empty before the initialization).
  std::set<SensorId> estimatedAnchorIds() const;
  /// Before any input: a restart. At the first IMU sample, if it is at most `init.resume_max_age_s`
  /// newer than c.t, the estimated anchors and the baro reference and bias come back from `c`, and
  /// the pose too when the outage is at most `init.resume_max_outage_s` (else the pose is
  /// initialized as usual: in flight by the MotionAligner). Older: counted "resume_refused".
  void resumeFrom(EstimatorCheckpoint c) { resume_.offer(std::move(c)); }
  /// A re-run computed on a worker (`refine.rerun_mode` async) has not been swapped in yet.
  bool rerunRunning() const { return rerun_.running(); }
  /// Waits for the running re-run, swaps it in and runs (and waits for) a re-run queued behind it:
  /// a deterministic point for tests and the end of a replay or of the process.
  void finishRerun();
  /// Shutdown without waiting: swaps a finished worker re-run in, abandons one still running.
  void stopRerun() {
    rerun_.poll(false, timeline_, *this);
    rerun_.abandon();
  }

 private:
  friend class EstimatorNodeTesting;  ///< the test hooks (estimator/testing/estimator_node_testing.h)
  /// A fault in the pose (EstimatorNodeTesting::injectPoseError).
  void injectPoseError(const Eigen::Vector3d& dp_m, double dyaw_rad);
  /// The node without the start-up report: a re-run's replay node (launchRerun), whose setup the
  /// live node has reported already.
  struct Quiet {};
  EstimatorNode(const EstimatorOptions& options, const SystemSetup& setup, EstimatorSinks sinks, Quiet);
  /// Known anchors whose horizontal positions lie nearly on one line (AnchorLayout): a warning and
  /// the counter `known_anchors_nearly_collinear`, unless they lie in a wall of the flight volume
  /// (plane_mirror_ then tells the two sides apart).
  void reportSetupGeometry();
  struct GravityAdapter;  ///< the node as GravityDirection's context (estimator_node_gravity.cpp)
  /// What GravityDirection has due at IMU time `t` (comparison, re-initialization with +z).
  void runGravityDirection(Timestamp t);
  /// The clock jumped back past everything the node holds: it starts over, streams forgotten.
  void startOverAfterClockBack();
  /// Before initialization: `in` waits in the settler until nothing earlier can still arrive
  /// (InputSettler), then the settled inputs are routed in the canonical order.
  void settle(const EstimatorInput& in);
  /// An admitted input on its way: held for the next IMU sample (holdForNextImu) or accepted.
  void route(const EstimatorInput& in);
  /// Before initialization: the input to the initializers (anchors held for later).
  void feedInitializer(const EstimatorInput& in);
  void initialize(const InitialBelief& b);
  /// The initialization's log lines (pose, σ, source, heights, a missing baro reference).
  void logInitialization(const InitialBelief& b) const;
  /// Processes one input on `cur_`; `first` = first time (count events, publish).
  void process(const EstimatorInput& in, bool first);
  void processImu(const ImuSample& s, bool first);
  void processBaro(const BaroSample& s, bool first);
  void processRange(const RangeSample& s, bool first);
  /// A fleet's inter-vehicle range (docs/fleet.md "Inter-vehicle ranges"): the peer's tag as an
  /// exactly known point for this update, its covariance added along the line of sight to R.
  void processPeerRange(const PeerRange& p, bool first);
  /// A range re-processed (not first) with another gate decision than it was counted with: its two
  /// instances' counts move to the new decision (range_fates_).
  void recountRange(const RangeSample& s, SensorId a, SensorId b, bool accepted);
  void processHeight(const HeightSample& s, bool first);
  void processZupt(const ImuSample& s, bool first);
  /// Instance statistics, health and the "gated_<type>" counter of a scalar update (baro, height).
  void countScalarUpdate(Timestamp t, SensorId id, const std::string& type, const UpdateResult& r);
  void applyAnchorInit(const AnchorInit& a, bool first);
  void applyCommand(const EstimatorCommand& c, bool first);
  /// Propagates to a measurement's time `t` past the last IMU sample, with the readings
  /// interpolated towards next_imu_ when known, else extrapolated along the last two samples to
  /// the step's middle (ImuPropagation::toTime, imu_readings.h).
  void propagateTo(Timestamp t);
  /// Runs `propagate` (a propagation of cur_'s filter) and gives the fixed-lag smoother its record:
  /// the IMU block before and after and the transition between.
  template <class Propagate>
  void propagateRecorded(Propagate&& propagate);
  /// What ImuPropagation reads besides the filter (cur_'s samples, mean reading, g, λ).
  ImuPropagation::Inputs propagationInputs() const;
  /// Gravity in G: (0, 0, ∓|g|) by the gravity direction's sign.
  Eigen::Vector3d gravityG() const { return gravity_.gravityG(options_.gravity_m_s2); }
  /// Baro readings or heights seen (both measure along −z of G).
  bool hasVerticalSensor() const;
  /// Re-initializes the pose from the aligner with gravity along +z (anchors and biases kept, as
  /// a recovery); false when the aligner refuses now.
  bool reinitializeWithPlusZ(Timestamp t);
  void updateHealth(Timestamp t);
  void tryRecover(Timestamp t);
  /// The flight volume's models on the estimate (FlightVolumeGuard): a mirror image is reflected
  /// into the volume, else the position is truncated to the volume's side of the anchors' plane.
  void checkFlightVolume(Timestamp t);
  /// Replaces the IMU instance (state, covariance, time); every other instance keeps its mean and
  /// marginal covariance (cross-covariances dropped), but the UWB clock's offset, which returns to
  /// its prior (setUwbClockPrior). History before `t` is forgotten.
  void replaceImu(const ImuState& x, const ImuMatrix& P, Timestamp t, const ImuSample& last_imu);
  /// Puts the UWB clock's offset instance (ClockOffsetKind) in `f` with its prior from setup.yaml
  /// `uwb_clock` / `uwb.clock_offset_sigma_s`, replacing the one there, when that σ is > 0 and
  /// ranges are used. At initialization, and when a re-initialization replaces a pose that was
  /// wrong: the offset's only information is the ranges against that pose's motion (a gravity
  /// flipped for 8 s on ISAS-Walk1 took it to −158 ms, −4 ms after it), so it starts again.
  void setUwbClockPrior(FusionStrategy& f) const;
  /// Starts the pending re-run (AnchorRerun::start), a worker's replay node made by makeReplayNode.
  void startRerun();
  /// A replay node for a worker re-run: this node's options and setup, without the start-up report,
  /// with what processing reads besides the context (stillness, baro reference, height bias prior,
  /// joined anchors, gravity direction, IMU-gap window, ZUPT model, re-entry fates).
  std::unique_ptr<RerunReplayer> makeReplayNode() const;
  /// The anchors held before initialization (or from a resumed checkpoint), applied at `t` with
  /// their own covariance (no re-run).
  void applyHeldAnchors(Timestamp t);
  /// Re-processes the entries after `it` on cur_ (refreshing their snapshots), as replays do.
  void replayAfter(InputTimeline::Window::iterator it);
  /// The next IMU sample of the stored input at `it` (nextImuSample), or for the newest one the
  /// sample releasing it (releaseHeld).
  std::optional<ImuSample> nextImuInWindow(InputTimeline::Window::iterator it) const;
  /// With `imu.hold_for_next_sample`, a measurement stamped after the last IMU sample (by at most
  /// `imu.max_dt_s`) is held until the sample after it has come (true: held). The two parts of the IMU step it cuts are then propagated on readings
  /// interpolated between known samples, which integrate to the uncut step's: extrapolating the
  /// first part instead integrates −(Δt/8)(u_{k+1} − 2u_k + u_{k−1}) more per cut step, and ranges
  /// at a fixed phase of the IMU's period rectify a rotor's vibration into a steady drift
  /// (docs/modular_estimator.md "Readings between IMU samples"). POSE is published at IMU samples,
  /// so the wait delays no output.
  bool holdForNextImu(const EstimatorInput& in);
  /// Processes the held measurements, in the canonical order: before `next`'s time with `next` as
  /// their next sample (`at_its_time` false, before `next` itself is processed), or at its time
  /// (true, after it); all of them on extrapolated readings when `next` is nullopt (an IMU gap,
  /// the end of the stream).
  void releaseHeld(const std::optional<ImuSample>& next, bool at_its_time);
  /// `next`, or when it is empty and `in` a measurement, the sample being released (releaseHeld)
  /// if it comes at most imu.max_dt_s after `in`: what follows the stored inputs.
  std::optional<ImuSample> orReleasingSample(const EstimatorInput& in, std::optional<ImuSample> next) const;
  /// The input after the gates (time, duplicates, units) and the hold: initializers, window, filter.
  void accept(const EstimatorInput& in);
  /// Every re-initialization of the pose (initialize, replaceImu): the timeline forgets what a
  /// rewind or a re-run could restore from before `t`, a running re-run is dropped, the health
  /// window restarts.
  void onReinitialized(Timestamp t);
  // RerunReplayer: the node re-processing stored inputs for AnchorRerun.
  FilterContext& replayContext() override { return cur_; }
  void replay(const EstimatorInput& in, const std::optional<ImuSample>& next_imu) override {
    if (options_.imu.hold_for_next_sample) next_imu_ = orReleasingSample(in, next_imu);  // else extrapolated, as the first time
    process(in, false);
    next_imu_.reset();
  }
  std::optional<double> nextImuSpan_s() const override {
    return options_.imu.hold_for_next_sample ? std::optional<double>(options_.imu.max_dt_s) : std::nullopt;
  }
  void replayAnchor(const AnchorInit& a) override { applyAnchorInit(a, false); }
  /// Releases the ranges held after a gap once uwb.reentry_hold_s passed (ReentryGate decides),
  /// then the node rewinds to the first held range and re-processes from there.
  void releaseReentryIfDue();
  void event(bool first, const std::string& kind, const std::string& message = "");
  void publishPeriodic();
  void resetAll();

  EstimatorOptions options_;
  SystemSetup setup_;
  EstimatorSinks sinks_;
  Diagnostics diag_;
  StepTimings timings_;
  InputGate gate_;
  /// The IMU's units (m/s², rad/s): a stream in other units stops the estimator with the reason
  /// (waitingFor), counter `imu_units_implausible`; only a Reset command starts it again.
  ImuUnitsCheck imu_units_;
  Initialization init_;
  /// Inputs before the initialization, until settled (init.settle_max_s).
  InputSettler settler_;
  GravityDirection gravity_;
  FlightVolumeGuard volume_;
  OutputSchedule outputs_;
  /// One model per sensor: each turns its input into an update of the filter.
  struct SensorModels {
    BaroUpdater baro;
    HeightUpdater height;  ///< downward rangefinder, or a carried rig's height
    RangeUpdater range;
    AnchorJoin anchor_join;
    ImuPropagation imu;
    ZuptModel zupt;
  };
  SensorModels sensors_;

  HealthMonitor health_;
  RecoveryPolicy recovery_;
  RecoveryConfirmation recovery_confirmation_;
  ReentryGate reentry_;
  Resume resume_;  ///< resumeFrom's checkpoint, until the initialization

  FilterContext cur_;
  /// Measurements waiting for the IMU sample after them (holdForNextImu), in arrival order.
  std::deque<EstimatorInput> held_for_imu_;
  /// The IMU sample after the input being processed, when known (propagateTo); set around process().
  std::optional<ImuSample> next_imu_;
  /// The sample releasing the held measurements (releaseHeld), while it does.
  std::optional<ImuSample> pending_next_imu_;
  InputTimeline timeline_;
  AnchorRerun rerun_;
  std::map<SensorId, InstanceStatus> instance_stats_;
  /// Each counted range in the out-of-sequence window: fused (true) or gated at its last processing,
  /// so that a rewind that changes the decision moves its count (recountRange); pruned with the window.
  std::map<InputOrder, bool> range_fates_;
  FixedLagSmoother smoother_;  ///< enabled by fixed_lag.enabled and a pose_smoothed sink
};

}  // namespace meshnav::estimator
