#pragma once
/// @file estimator_options.h
/// @brief Tuning of the estimator (config/estimator.yaml). Loading follows the one rule of
/// common/yaml_options.h: an unknown key or a bad value is an error naming the file and the key, a
/// missing key keeps its default; the defaults here equal the shipped file. Setup noise figures (setup.yaml `noise:`)
/// override the matching defaults at construction of the node (see `applySetupNoise`).

#include <cmath>
#include <string>

#include "common/chi_square.h"
#include "common/setup.h"
#include "common/time_guard.h"
#include "estimator/health/health_monitor.h"
#include "estimator/imu/process_noise_adapter.h"

namespace meshnav::estimator {

/// IMU noise model (continuous-time densities).
struct ImuNoiseOptions {
  double acc_noise_density = 0.02;    ///< σ_a [m/s²/√Hz]
  double gyro_noise_density = 0.002;  ///< σ_ω [rad/s/√Hz]
  double acc_bias_rw = 0.002;         ///< σ_ba [m/s³/√Hz]
  double gyro_bias_rw = 0.0002;       ///< σ_bω [rad/s²/√Hz]
  double max_dt_s = 0.1;              ///< a longer IMU gap is counted ("imu_gap") and inflated [s]
  /// An update between two samples propagates on the readings extrapolated along the last two
  /// samples when these are at most this far apart, else on the last one held (imu_readings.h):
  /// a slope over a longer span says nothing about the next few ms. 0: always held [s]
  double extrapolate_max_period_s = 0.02;
  /// A measurement stamped after the last IMU sample waits for the next sample, so that its
  /// propagation interpolates between known samples (EstimatorNode::holdForNextImu); false: it is
  /// processed at once on extrapolated readings. Off by default for now: it removes the
  /// rectification of a rotor's vibration (widened run001 0.098 → 0.061 m), but two robustness
  /// cases (RobustNode.TheFirstRangesAfterARangeGap…, …OneTagLawnmowerOffTheMirrorImage) fail
  /// with it and MILUV ifo002 goes 1.006 → 1.074 m (docs/modular_estimator.md, "Held for the
  /// next sample").
  bool hold_for_next_sample = false;
  /// Beyond `max_dt_s` after the last IMU sample the filter runs on the readings `gap_readings`
  /// says; their error is modelled as white noise of these densities (docs/robustness.md, "IMU gaps").
  double gap_sigma_acc_m_s2 = 1.0;    ///< [m/s²/√s]
  /// Attitude is not inflated by default: with no accelerometer data in the gap, an inflated tilt
  /// lets range updates explain position innovations by tilt, which leaks gravity afterwards
  /// (measured on a 3 s dropout: 15 m with 0.1 rad/s/√s, 7 m with 0; the recovery then fixes it).
  double gap_sigma_gyro_rad_s = 0.0;  ///< [rad/s/√s]
  /// What the filter propagates on in a gap: "mean" (the acceleration in G and the angular rate
  /// low-passed with `gap_mean_time_constant_s`: a steady turn continues, an oscillation such as a
  /// gait is averaged out),
  /// "still" (no acceleration in G, no rotation: the vehicle keeps its velocity and attitude) or
  /// "held" (the last reading repeated, which integrates a momentary rotation rate over the whole
  /// gap; before 2026-12-04 the only way).
  std::string gap_readings = "mean";
  double gap_mean_time_constant_s = 0.5;  ///< low-pass of the readings for gap_readings "mean" [s]
};

/// Static initialization while landed.
struct InitOptions {
  double duration_s = 1.0;              ///< landed data needed before initializing [s]
  int min_ranges = 12;                  ///< tag–known-anchor ranges needed without initial_pose
  /// No FLIGHT_STATE yet: treat as landed. Off by default: without a flight state the IMU's own
  /// stillness (zupt.detect_stillness) is the evidence of rest.
  bool assume_landed_without_flight_state = false;
  double sigma_v_m_s = 0.05;            ///< initial velocity σ [m/s]
  double sigma_roll_pitch_deg = 2.0;    ///< initial roll/pitch σ [deg]
  double sigma_bias_gyro_rad_s = 0.005; ///< initial gyro bias σ [rad/s]
  double sigma_bias_acc_m_s2 = 0.2;     ///< initial accelerometer bias σ [m/s²]
  double range_init_min_sigma_p_m = 0.2;   ///< floor of the position σ from range least squares [m]
  double range_init_sigma_yaw_deg = 30.0;  ///< yaw σ when initialized from ranges (large) [deg]
  double range_init_outlier_m = 0.6;       ///< residual beyond which an init range is dropped [m]
  /// Static range fit: refuse (and wait for motion) while yaw is less certain than this [deg].
  double static_max_sigma_yaw_deg = 20.0;
  /// Range fits (static and in motion): a second minimum elsewhere whose cost is within this of
  /// the best makes the pose ambiguous (refused) [-]
  double ambiguity_chi2 = 16.0;
  double motion_window_s = 12.0;            ///< in-motion alignment: data window [s]
  /// Before the initialization, an input goes to the initializers once every stream has passed
  /// its stamp (InputSettler), or at the latest when it is this much older than the newest input:
  /// a stream stopped for longer no longer holds the others back [s]
  double settle_max_s = 2.0;
  /// Before the scheduled gravity check (a `motion_window_s` after the first initialization): a
  /// batch median range NIS (process_noise: every `batch` ranges, so only with it enabled) at
  /// least this many times its expected value runs the check at once (once; it acts only on a
  /// decisive +z); 0 = never [-]
  double gravity_early_check_nis_ratio = 6.0;
  /// In-motion alignment: with fewer than `motion_min_ranges` ranges in `motion_window_s` (sparse
  /// ranging), the window reaches back until it holds them, at most this far [s]
  double motion_max_window_s = 40.0;
  double motion_min_span_s = 3.0;          ///< in-motion alignment: shortest window [s]
  int motion_min_ranges = 20;              ///< in-motion alignment: tag–anchor ranges needed [-]
  /// In-motion alignment: refuse above [deg]. 15° rather than 25°: hover windows aligned at
  /// σ_yaw 15–24° left the filter heading errors of 25–60° it did not pull back (docs/robustness.md)
  double motion_max_sigma_yaw_deg = 15.0;
  double motion_max_sigma_p_m = 0.5;       ///< in-motion alignment: refuse above [m]
  /// In-motion alignment: integrate the window again at the fitted gyro bias when its correction
  /// turns the attitude by more than this over the window; 0 = never [rad]
  double motion_relinearize_rad = 0.02;
  /// Baro heights against the setup's reference pressure as the in-motion alignment's vertical
  /// constraint (not with a carried height): nearly coplanar anchors then cannot mirror the height.
  bool motion_use_baro = true;
  double resume_max_age_s = 5.0;           ///< a checkpoint (resumeFrom) older than this is not used [s]
  double resume_max_outage_s = 0.5;        ///< longer outages re-initialize the pose (anchors still kept) [s]
  double resume_max_acc_m_s2 = 3.0;        ///< largest acceleration assumed during the outage [m/s²]
  double resume_max_rate_deg_s = 30.0;     ///< largest rotation rate assumed during the outage [deg/s]
};

struct BaroOptions {
  bool enabled = true;
  double pressure_sigma_pa = 3.0;        ///< pressure noise σ [Pa]
  double bias_rw_m_per_sqrt_s = 0.02;    ///< height bias random walk [m/√s]
  double init_bias_sigma_m = 1.0;        ///< bias σ when the reference pressure is given [m]
  double gate_probability = 0.999;       ///< χ² gate (0: no gating) [-]
};

/// Downward laser rangefinder (height.csv, estimator/height/): range to a flat floor at z = 0 in
/// G along the body's −z axis, plus a bias state (the sensor's offset from the IMU along z when
/// setup.yaml gives no `height.p_IH`, and floor unevenness).
struct HeightOptions {
  bool enabled = true;
  double sigma_m = 0.05;                 ///< range noise σ [m]
  double bias_rw_m_per_sqrt_s = 0.01;    ///< bias random walk [m/√s]
  double init_bias_sigma_m = 0.3;        ///< prior σ of the bias around 0 [m]
  double gate_probability = 0.999;       ///< χ² gate (0: no gating) [-]
  /// Readings below are not used: laser rangefinders clamp at the bottom of their range (MILUV's
  /// reads 0.29 m while the drone stands on the floor) [m]
  double min_range_m = 0.3;
  bool tilt_correction = true;           ///< h = p_z / cos(tilt) (else h = p_z)
  double max_tilt_deg = 30.0;            ///< not used while the body is tilted more [deg]
  /// Fed to the in-motion alignment (MotionAligner) as a vertical constraint (removes the mirror
  /// image across nearly coplanar anchors), thinned to this rate [Hz]; 0: not used there.
  double align_rate_hz = 5.0;
};

/// A hand-held rig carried at a roughly constant height (setup.yaml `carried_height`, docs/robustness.md
/// "Carried height"): a pseudo-reading h = height_m of the height model without lever arm or tilt
/// correction, h = p_z + b_C, whose bias instance b_C (prior σ from the setup) takes the unknown
/// carrying height and its slow changes; the reading's own σ covers the gait's bob. It uses the
/// height sensor's instance (setup `height_id`): a real height.csv is then ignored and counted.
struct CarriedHeightOptions {
  bool enabled = true;                   ///< used when setup.yaml has `carried_height`
  double rate_hz = 2.0;                  ///< pseudo-readings per second of IMU time [Hz]
  double sigma_m = 0.05;                 ///< σ of one reading (gait bob and sway) [m]
  double bias_rw_m_per_sqrt_s = 0.02;    ///< random walk of the carrying height [m/√s]
};

struct UwbOptions {
  bool enabled = true;
  double sigma_range_m = 0.15;           ///< fallback range σ [m]
  double gate_probability = 0.997;       ///< χ² gate (0: no gating) [-]
  /// Huber threshold of the range update in innovation σ's (Linearization::huber_k; 0: off).
  double huber_k = 0.0;
  /// ... while H P Hᵀ / R of the range is at most this (Linearization::huber_max_prior_ratio) [-]
  double huber_max_prior_ratio = 1.0;
  bool use_corrected_range = false;      ///< fuse range_corr instead of range_raw
  double max_range_m = 100.0;            ///< longer ranges are bad input [m]
  /// Estimate γ of tag–setup-anchor pairs whose a-priori bias has sigma_gamma > 0 as states of the
  /// tag instances (else their σ_γ inflates the range noise).
  bool estimate_tag_biases = true;
  /// The constant bias of a tag–setup-anchor pair that setup.yaml `pair_biases` does not list
  /// (docs/uwb_bias_model.md). Every UWB pair has one (antenna delays, the received-power bias;
  /// STAR-loc's raw ranges +0.09 to +0.39 m): γ(tag, a) = c_tag + e(tag, a), c_tag the offset
  /// common to the tag's pairs (N(0, uncalibrated_common_gamma_sigma_m²)), e the pair's own part
  /// (N(0, σ²), σ this value [m]). With `estimate_tag_biases` the γ are states of the tag's
  /// instance with that prior (covariance σ_c² 11ᵀ + σ² I); else σ_c² + σ² inflates the pair's
  /// range noise. 0: an unlisted pair is exact (γ = 0; calibrated ranges, setup `noise.sigma_gamma: 0`).
  /// Default 0.1 m, the measured spread (docs/uwb_bias_model.md).
  double uncalibrated_gamma_sigma_m = 0.1;
  /// σ_c of the common part above [m]. Model parameter: the STAR-loc run is the same to 1 mm for
  /// 0.2–1.0 m (the data fix c), so it is a wide prior, not a tuning.
  double uncalibrated_common_gamma_sigma_m = 0.5;
  /// Correlation time τ of a pair's range error once its γ is removed [s] (RangeErrorCorrelation:
  /// a range Δt after its pair's previous one is fused with R (1 + ρ)/(1 − ρ), ρ = e^(−Δt/τ)).
  /// Model parameter: STAR-loc's errors against its truth have autocorrelation 0.52 at 0.1 s (one
  /// pair's ranges 0.072 s apart), which a first-order process has at τ ≈ 0.1 s; ranges of a pair
  /// seconds apart (MILUV's) are unchanged. 0: white errors. setup.yaml `noise.range_correlation_time`
  /// overrides it: the simulator, whose errors are drawn independently, writes 0. The step weights
  /// a range by (1 + ρ)/(1 − ρ) R; its gate and NIS judge it by R (Linearization::step_noise_factor).
  double range_error_correlation_s = 0.1;
  /// Prior σ of the UWB clock's delay against the IMU clock (ClockOffsetKind) when setup.yaml
  /// `uwb_clock.sigma_s` gives none [s]; 0: the offset is not a state (setup's `uwb_clock.offset_s`,
  /// default 0, is applied as a constant). Model parameter: host-stamped streams put tens of
  /// milliseconds between the two (STAR-loc's IMU leads its ranges by about 30 ms, issue 34); at a
  /// walk the data fix the delay only slowly (σ 50 → 23 ms over STAR-loc's 34 s), so the prior
  /// matters: 0.05 s let it wander to −75 ms there, 0.03 s gives −52 ms, 0.02 s −34 ms
  /// (docs/uwb_bias_model.md, "Clock offset"). The simulator writes 0 for clocks it draws as one.
  double clock_offset_sigma_s = 0.03;
  /// Random walk of that delay [s/√s] (two free-running clocks drift apart; 1e-4 s/√s lets it move
  /// 1 ms in 100 s).
  double clock_offset_rw_s_per_sqrt_s = 1e-4;
  /// A range's error is a line-of-sight / NLOS mixture (estimator/core/nlos_mixture.h): with prior
  /// probability `nlos_fraction` a positive excess nlos_min_excess_m + Exp(nlos_mean_excess_m); a
  /// range that passed the gate updates the state by the mixture's posterior collapsed to one
  /// Gaussian (only while the measurement dominates its innovation, as the Huber weight:
  /// huber_max_prior_ratio).
  /// b₀ and μ are model parameters, from STAR-loc's errors against its truth (γ removed): beyond
  /// +0.2 m 10.1 % of them, below −0.2 m 4.2 % (about 6 % excess on the positive side), mean
  /// excess beyond 0.2 m 0.35 m. ε is an option, 0.1 by default: STAR-loc's ranges more than
  /// b₀ above their pair's median error (10.0 %); 0 = Gaussian ranges only (docs/uwb_bias_model.md,
  /// "NLOS excess").
  double nlos_fraction = 0.1;
  double nlos_min_excess_m = 0.2;   ///< b₀ [m]
  double nlos_mean_excess_m = 0.3;  ///< μ [m]
  /// Whole a-priori σ of an unlisted pair's γ, √(σ_c² + σ²) (0 when such a pair is exact) [m].
  double uncalibratedPairSigma() const {
    return uncalibrated_gamma_sigma_m > 0.0 ? std::hypot(uncalibrated_common_gamma_sigma_m, uncalibrated_gamma_sigma_m)
                                            : 0.0;
  }
  /// Estimate the γ of an anchor added at run time (ANCHOR_INIT: its calibrated biases with
  /// sigma_gamma > 0) as states of the anchor's instance (issue 10). Else they are fixed
  /// dictionary values whose σ_γ inflates the range noise.
  bool estimate_anchor_biases = true;
  /// The same for a known-but-uncertain setup anchor: its a-priori γ towards exactly known anchors
  /// and towards uncertain anchors of smaller id. Off by default: DP gains (docs/results.md) but
  /// DAH loses its private anchor–exact-anchor updates as position information and becomes
  /// overconfident on one sequence (seed 10: position ANEES 9.4).
  bool estimate_setup_anchor_biases = false;
  /// Fuse ranges between two anchors that both came from a calibration (ANCHOR_INIT), in every
  /// strategy. Off by default: their calibrations share the estimated trajectory (and one may be
  /// the other's reference), so their errors are correlated in a way ANCHOR_INIT does not carry;
  /// fused as independent they made DP overconfident (S2: final anchor NEES ≤ 13.93 for 37 % of
  /// the anchors, 93 % without them; docs/modular_estimator.md, "Anchor γ as states").
  bool fuse_calibrated_anchor_pairs = false;
  /// Initialize those states with the calibration's joint covariance of position and γ (when
  /// ANCHOR_INIT carries it); false: block-diagonal (position, independent σ_γ²), for comparison.
  bool anchor_bias_joint_covariance = true;
  /// Strategy `dah` only: fuse ranges between two estimated anchors. Off by default: DAH keeps no
  /// correlation between anchors that is built through a third instance (their common-mode error),
  /// so these updates shrink both anchors' covariance for information they share and make the
  /// filter overconfident (docs/modular_estimator.md, "DAH and anchor–anchor ranges"). Ranges
  /// between an estimated and an exactly known anchor are private updates and always fused.
  bool dah_fuse_estimated_anchor_pairs = false;
  /// Strategy `dah` only: which estimated anchors form a joint set (FactorizedCovariance::joinSet),
  /// i.e. are always updated together so that their mutual correlation is exact (issue 10):
  /// `none`; `batch`: the anchors added together (one batch of ANCHOR_INITs between two other
  /// inputs, and the anchors a re-run adds at its start); `all`: every anchor added at run time.
  std::string dah_joint_anchors = "batch";
  /// Strategy `dah` only: the tags' γ instances (TagBiasKind) join that set too. A tag range to an
  /// exactly known anchor updates {IMU, tag}; the tag's γ and the anchors become correlated through
  /// the pose, and DAH without this drops that correlation. Since every set then holds the tags,
  /// the batches merge into one set with them.
  bool dah_joint_tag_biases = true;
  /// Strategy `dah` only: the IMU joins that set too, so that every update of the pose (baro,
  /// ZUPT, ranges to exactly known anchors) also corrects the set's anchors through their
  /// correlation with the pose, as the exact filter does. The baro and height-sensor bias
  /// instances come with it: ranges correlate them with every member through the pose, and
  /// outside the set they left every member a pair for the DAH correction on every update (its
  /// cost; docs/modular_estimator.md, "Joint sets", "Cost").
  bool dah_joint_imu = true;
  /// Strategy `dah` only: at most this many estimated anchors in a joint set (0: no bound). A set
  /// that holds the IMU is stacked by every update, so without a bound every anchor calibrated on
  /// a long flight joins it and DAH's update grows with them. When a join exceeds the bound, the
  /// anchors whose position covariance has the smallest trace (the most refined; ties: the smaller
  /// id) leave the set, never the joining anchor: their correlations stay and are DAH's from then
  /// on (updated exactly only by an update that names them).
  int dah_joint_max_anchors = 8;
  /// Ranges after an aiding gap (issue 8, docs/robustness.md "Range gaps"): when no tag–anchor
  /// range was accepted for `reentry_gap_s`, the tag ranges of the next `reentry_hold_s` are held,
  /// tested against each other (ReentryCheck; with at least `reentry_min_ranges` from
  /// `reentry_min_anchors` anchors, else all are fused) and the agreeing ones fused at their own times.
  double reentry_gap_s = 2.0;             ///< gap that starts a hold, 0 = off [s]
  double reentry_hold_s = 0.5;            ///< longest hold, at most window_s [s]
  int reentry_min_ranges = 4;             ///< held ranges needed to test them against each other [-]
  int reentry_min_anchors = 3;            ///< distinct anchors among them [-]
  double reentry_gate_probability = 0.999;  ///< leave-one-out χ²₁ gate [-]
};

struct ZuptOptions {
  bool enabled = true;
  double rate_hz = 10.0;                 ///< pseudo-measurement rate while landed [Hz]
  double sigma_acc_m_s2 = 0.2;           ///< σ of a = 0 [m/s²]
  /// σ of ω = 0 beyond the gyro noise: the rotation a body the flight state calls landed may still
  /// have [rad/s]. The ω row fuses the mean reading since the last ZUPT with
  /// σ² = sigma_gyro_rad_s² + σ_ω²/T (RestRateMean), σ_ω the gyro noise density, T the interval.
  double sigma_gyro_rad_s = 0.001;
  double sigma_vel_m_s = 0.02;           ///< σ of v = 0 [m/s]
  /// Without FLIGHT_STATE: zero-velocity updates while the IMU itself shows rest (StillnessDetector).
  /// An IMU cannot tell rest from constant velocity, so these updates are χ²-gated against the
  /// filter's own velocity (probability `stillness_gate_probability`); flight-state ZUPTs are not.
  bool detect_stillness = true;
  double stillness_gate_probability = 0.999;  ///< [-]
  /// σ of v = 0 and of ω = 0 when only the IMU's stillness says rest (no FLIGHT_STATE), also the
  /// velocity and gyro-bias σ of a static initialization on that evidence. A smooth hover or a
  /// slowly pushed rig is "still" to the detector while it drifts at up to about 0.1 m/s and turns
  /// at up to the detector's mean-rate limit (0.02 rad/s); the flight-state values (σ 0.02 m/s)
  /// pinned such a hover's velocity at zero and its range NIS at 4–8× (docs/robustness.md).
  double stillness_sigma_vel_m_s = 0.1;      ///< [m/s]
  double stillness_sigma_gyro_rad_s = 0.02;  ///< [rad/s]
};

/// The fixed-lag smoother beside the filter (FixedLagSmoother, docs/smoother.md).
struct FixedLagOptions {
  /// Smallest age of a smoothed pose: the data after it that it holds; 0 = no smoothed poses
  /// (POSE_SMOOTHED, estimate_smoothed.csv) [s]
  double lag_s = 2.0;
  /// Model parameter: data time between two backward passes (the lag is lag_s … about
  /// lag_s + 2 period_s). Each record is visited (lag_s + period_s) / period_s times: 1 s keeps the
  /// smoother's CPU near the filter's at 200 Hz (docs/smoother.md) [s]
  double period_s = 1.0;
  bool enabled() const { return lag_s > 0.0; }
};

/// Re-initialization when the health monitor reports `lost`.
struct RecoveryOptions {
  bool enabled = true;
  double retry_s = 1.0;                  ///< between two alignment attempts while lost [s]
  /// While `degraded`, also align every `retry_s` and re-initialize when the aligned pose and the
  /// filter's disagree beyond this χ² (4 dof: position and yaw, both covariances) [-]; 0: off.
  double degraded_disagreement_chi2 = 23.5;
  /// After an IMU gap at least this long, for `init.motion_window_s`, the same comparison as while
  /// degraded (the gap's dead reckoning may be metres off before the gate notices) [s]; 0: off.
  double after_gap_check_min_s = 1.0;
};

/// The setup's `flight_volume` (docs/robustness.md "The flight volume"): initialization drops fits
/// outside it, and against the mirror image across coplanar known anchors on its walls or ceiling
/// (AnchorPlaneMirror) the filter keeps to the volume's side of their plane.
struct FlightVolumeOptions {
  bool enabled = true;
  /// An estimate this far outside the volume whose mirror image is inside is reflected into it [m].
  double mirror_margin_m = 0.1;
  /// The vehicle is on the volume's side of the anchors' plane: the position's Gaussian is
  /// truncated to that side at most this often (Simon's PDF truncation, as a pseudo-measurement
  /// along the plane's normal); 0: never [Hz].
  double side_constraint_rate_hz = 10.0;
  /// Initialization and re-alignment: a fit that ends farther outside the volume is no candidate
  /// (neither the pose nor a rival that makes the data ambiguous) [m].
  double candidate_margin_m = 0.5;
};

/// Anchor refinement (issue 10): a second pass when a calibrated anchor joins. The calibration used
/// the filter's trajectory, so refining the calibrated belief forward cannot undo the trajectory's
/// error (docs/results.md, "What limits the refinement"); estimating the anchor jointly with the
/// trajectory from the start can. On ANCHOR_INIT the node restores its oldest stored state and
/// re-processes every stored input with the calibrated anchors as uncertain anchors from there:
/// mean = the calibration, position σ `rerun_prior_sigma_m` per axis, γ σ `rerun_gamma_sigma_m`
/// (loose, since the ranges that made the calibration are fused again), then continues live.
struct RefineOptions {
  bool rerun_on_anchor_join = true;      ///< re-run from the oldest stored input on ANCHOR_INIT
  /// Inputs are kept this long for re-runs (≈ 260 B per input, S2 360 inputs/s: 28 MB at 300 s,
  /// plus 8 checkpoints); older inputs are dropped in eighths and counted ("rerun_history_cut").
  /// A re-run costs about the live processing of the same data (S2, DP, 5 anchors: 0.85 s wall
  /// for 99 s) and blocks the node meanwhile [s]
  double max_history_s = 300.0;
  double rerun_prior_sigma_m = 0.3;      ///< position σ per axis of a calibrated anchor in a re-run [m]
  double rerun_gamma_sigma_m = 0.25;     ///< σ of its γ in a re-run (no joint covariance) [m]
  /// The γ means of a re-run: the calibration's (true) or the calibrator's prior mean 0 (false).
  bool rerun_gamma_from_calibration = false;
  /// Strategy `dah` too. With the joint set of the re-run's anchors and the tags' γ
  /// (uwb.dah_joint_anchors, uwb.dah_joint_tag_biases) DAH reaches DP's refinement (S2: 0.115 →
  /// 0.063 m, DP 0.061 m); without the sets it did not gain (0.116 m; docs/results.md).
  bool rerun_with_dah = true;
  /// Where a re-run is computed: `sync` inline in the input handler (the node publishes nothing
  /// meanwhile: 0.1–0.4 s on S2, seconds under ASan), `async` on a worker thread from immutable
  /// copies while the node keeps publishing, swapped in at the first input after it is done (wall
  /// clock dependent, so not bit-for-bit repeatable), `auto`: async in the LCM estimator process,
  /// sync in in-process replays (meshnav_run, tests, paper tables), which stay deterministic.
  std::string rerun_mode = "auto";
};

struct EstimatorOptions {
  /// Which platform models are on (forProfile): `auto` (every model, each used when its input or
  /// setup entry is there), `drone` (no carried height), `handheld` (no downward rangefinder, no
  /// landed assumption without FLIGHT_STATE). The other keys of a file override the profile.
  std::string profile = "auto";
  std::string strategy = "centralized";  ///< a name of kStrategyList (estimator/core/strategy_list.h)
  double gravity_m_s2 = 9.81;            ///< |g|, gravity is −g along z of G [m/s²]
  double window_s = 1.0;                 ///< out-of-sequence window [s]
  double pose_output_rate_hz = 0.0;      ///< POSE rate; 0: every IMU step [Hz]
  double anchors_output_rate_hz = 1.0;   ///< ANCHORS rate (data time) [Hz]
  double status_rate_hz = 1.0;           ///< ESTIMATOR_STATUS rate (data time) [Hz]
  bool joseph_form = true;               ///< Joseph covariance update (else P − K S Kᵀ, symmetrized)
  ImuNoiseOptions imu;
  InitOptions init;
  BaroOptions baro;
  HeightOptions height;
  CarriedHeightOptions carried_height;
  UwbOptions uwb;
  ZuptOptions zupt;
  HealthOptions health;
  ProcessNoiseAdaptOptions process_noise;
  RecoveryOptions recovery;
  FlightVolumeOptions flight_volume;
  RefineOptions refine;
  FixedLagOptions fixed_lag;
  /// Inputs stamped far from the node's current time (common/time_guard.h): `time.max_offset_s`
  /// (>= window_s) and `time.rebase_after`.
  TimeGuardOptions time;

  /// Loads `path` (missing keys: defaults); throws std::runtime_error naming the file and the key
  /// for an unknown key, a value of the wrong type, a non-finite number or an out-of-range value.
  /// A key of the model parameters (fixed in code, docs/configuration.md) is refused naming the file
  /// and the key; `profile` is read first and gives the defaults (forProfile) the other keys override.
  static EstimatorOptions fromYaml(const std::string& path);
  /// The defaults of a profile (`auto`, `drone`, `handheld`); `profileListed` says which exist.
  static EstimatorOptions forProfile(const std::string& name);
  static bool profileListed(const std::string& name);
  /// Throws std::invalid_argument naming the first out-of-range value.
  void validate() const;
  /// Setup noise figures override the IMU and baro defaults (setup.yaml `noise:`). The range σ is
  /// resolved per range by `UwbNetwork` (pair σ, then setup σ, then the range's R, then this file).
  void applySetupNoise(const NoiseFigures& noise);
  /// Multi-line "key: value  # unit" listing of the options (the shipped file's form).
  std::string toString() const;
  /// The same listing of the model parameters (not loadable; docs/configuration.md).
  std::string modelParametersString() const;
};

/// χ² quantile (common/chi_square.h, Boost.Math).
using meshnav::chi2Quantile;

}  // namespace meshnav::estimator
