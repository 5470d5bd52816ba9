#pragma once
/// @file initialization.h
/// @brief How the estimator's first pose (and a re-alignment's) is found: the policy between the
/// landed initializer and the in-motion alignment, and what both are fed.
///
/// - **At rest** (a flight state says landed, else IMU stillness): StaticInitializer from the
///   landed data: roll and pitch from the mean specific force, gyro bias from the mean rate, the
///   position from the ranges (a robust multilateration), yaw from two tags or the initial pose.
/// - **In motion**, or when the landed data cannot fix the pose (one tag, coplanar anchors):
///   MotionAligner over a window of ranges, heights and strapdown increments, tried at most every
///   `kAlignRetry_s`.
/// - **Stillness**: every IMU sample goes through the StillnessDetector while no flight state was
///   received; its verdict per IMU time is kept for rewinds (`landedAt`), pruned by the node.
/// - **Heights for the alignment**: the baro against the setup's reference pressure when it aligns
///   (`init.motion_use_baro`, a reference given, no carried height), else the rangefinder or the
///   carried height, thinned to `height.align_rate_hz`.
///
/// Everything here is fed in arrival order (`feed`), before and after the filter's
/// initialization: the aligner is also what recovery and the gravity direction compare with.

#include <map>
#include <memory>
#include <optional>
#include <string>

#include "common/diagnostics.h"
#include "common/setup.h"
#include "estimator/core/estimator_options.h"
#include "estimator/filter/fusion_strategy.h"
#include "estimator/node/estimator_input.h"
#include "estimator/init/motion_aligner.h"
#include "estimator/init/static_initializer.h"
#include "estimator/node/step_timings.h"
#include "estimator/uwb/uwb_network.h"
#include "estimator/zupt/stillness_detector.h"

namespace meshnav::estimator {

class Initialization {
 public:
  /// An in-motion alignment is tried at most this often: a solve takes up to 0.4 s on a real
  /// recording (ISAS-Walk1), and the window changes little in less [s].
  static constexpr double kAlignRetry_s = 0.5;
  /// With no reference pressure in the setup, the baro reference is the pressure at the aligned
  /// height: its bias variance is the aligned height's plus this, for the one pressure reading the
  /// reference is: (dh/dp · baro.pressure_sigma_pa)² = (0.083 m/Pa · 3 Pa)² ≈ 0.062 m² near sea
  /// level, taken as 0.05 since the first in-motion alignment (kept: outputs unchanged) [m²].
  static constexpr double kBaroReferenceReadingVar_m2 = 0.05;

  /// `options` (with the setup's noise figures applied), `setup`, `diag` and `timings` must
  /// outlive this object.
  Initialization(const EstimatorOptions& options, const SystemSetup& setup, Diagnostics& diag, StepTimings& timings);

  /// Starts over (a node reset): a new landed initializer, an empty alignment window, gravity
  /// along −z. Stillness and the last pressure are kept (the stream goes on).
  void reset();
  /// Also forgets stillness, the flight state and the last pressure (the clock jumped back).
  void forgetStreams();

  /// An admitted input in arrival order: the aligner's window, stillness, flight state, pressure.
  /// Ranges need the network (tag or anchor) and, for estimated anchors, the filter (null before
  /// initialization).
  void feed(const EstimatorInput& in, const UwbNetwork& network, const FusionStrategy* filter);
  /// Before the filter is initialized: the input to the landed initializer; at an IMU sample, the
  /// belief to initialize with when one is found (landed, else in motion at `kAlignRetry_s`).
  std::optional<InitialBelief> tryInitialize(const EstimatorInput& in, bool landed);

  /// The aligner's fit of its window (timed as the step "align"), nullopt with `reason()`.
  std::optional<AlignmentResult> align(const Eigen::Vector3d& bias_gyro_rad_s,
                                       const std::optional<MotionAligner::HeadingPrior>& heading = std::nullopt);
  /// An alignment as an initial belief: the pose, the height bias it estimated, the baro's
  /// reference and bias. `landed`: the rest state at r.t.
  InitialBelief beliefFrom(const AlignmentResult& r, bool landed) const;
  /// Rest at IMU time `t`: `current` once a flight state decides; else the stillness detector's
  /// verdict; with stillness detection off, init.assume_landed_without_flight_state.
  bool landedAt(Timestamp t, bool current) const;
  /// Drops stillness verdicts before `oldest_us` [µs].
  void pruneStillness(int64_t oldest_us);

  /// Why the node is not initialized yet.
  std::string waitingFor() const;
  const std::string& alignerReason() const { return aligner_.reason(); }
  MotionAligner& aligner() { return aligner_; }
  /// A flight state was received: it, not stillness, says when the vehicle is landed.
  bool haveFlightState() const { return have_flight_state_; }
  /// Baro readings or aligner heights were seen (vertical sensors, along −z of G).
  bool sawVerticalSensor() const { return last_pressure_pa_ || last_align_height_; }
  /// The baro is the alignment's height source (`baroAligns(options, setup)`: init.motion_use_baro,
  /// baro.enabled, a setup reference pressure, no carried height): its heights are absolute.
  bool baroAligns() const { return baro_aligns_; }
  /// The setup's carried height is in use (a pseudo-sensor at the IMU rate).
  bool carriedHeight() const { return carried_height_; }
  /// The replay node of a re-run takes the live node's stillness and flight state.
  void copyStillnessFrom(const Initialization& live) {
    have_flight_state_ = live.have_flight_state_;
    still_at_ = live.still_at_;
  }

 private:
  void addAlignHeight(const AlignHeight& h);
  void feedHeight(const HeightSample& h);
  void feedBaro(const BaroSample& b);
  void feedRange(const RangeSample& r, const UwbNetwork& network, const FusionStrategy* filter);
  /// Before an in-motion alignment at IMU time `t`, until one decides: both gravity signs
  /// compared on the window (MotionAligner::checkGravityDirection); a decisive +z turns the
  /// aligner, so the pose is fitted with it (InitialBelief::gravity_z_sign). Not with baro or
  /// heights (they measure along −z of G).
  void compareGravitySigns(Timestamp t);

  const EstimatorOptions& options_;
  const SystemSetup& setup_;
  Diagnostics& diag_;
  StepTimings& timings_;
  bool carried_height_ = false, baro_aligns_ = false;
  std::unique_ptr<StaticInitializer> landed_;
  MotionAligner aligner_;
  StillnessDetector still_detector_;
  std::map<int64_t, bool> still_at_;  ///< stillness per IMU time [µs] (arrival order), pruned
  bool have_flight_state_ = false;
  std::optional<double> last_pressure_pa_;
  std::optional<Timestamp> last_align_height_;  ///< thinning of heights fed to the aligner
  std::optional<Timestamp> last_align_try_;
  int decided_sign_ = 0;  ///< gravity's sign along z of G decided on an alignment window (0: not yet)
};

/// The setup's carried height is used (setup `carried_height` and `carried_height.enabled`).
bool carriedHeightUsed(const EstimatorOptions& o, const SystemSetup& setup);
/// The barometer is the in-motion alignment's height source: `init.motion_use_baro` and
/// `baro.enabled`, the setup gives its reference pressure (absolute heights) and no carried height
/// is stated.
bool baroAligns(const EstimatorOptions& o, const SystemSetup& setup);
/// The height model's lever arm: the rangefinder's, or none for the carried height (h = p_z + b).
Eigen::Vector3d heightLever(const EstimatorOptions& o, const SystemSetup& setup);

}  // namespace meshnav::estimator
