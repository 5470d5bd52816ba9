#include "estimator/core/estimator_options.h"
#include "estimator/core/strategy_list.h"

#include "common/options_list.h"


#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace meshnav::estimator {
namespace {

/// Where an option lives: a pointer to the member, of one of the types an option may have.
using FieldRef = std::variant<double*, int*, bool*, std::string*>;
using Field = OptionField<EstimatorOptions, FieldRef>;

template <auto... path>
constexpr auto field = &memberAt<EstimatorOptions, FieldRef, path...>;

/// The strategies, as the shipped file's comment on `strategy` lists them.
const std::string kStrategyNames = strategyNames(" | ");

/// Every option, in the order of the shipped file (config/estimator.yaml): the single list used
/// for loading, printing and that file, so they cannot drift apart.
const Field kFields[] = {
    {"profile", field<&EstimatorOptions::profile>, "auto | drone | handheld: which platform models are on (docs/configuration.md); the keys below override it"},
    {"strategy", field<&EstimatorOptions::strategy>, kStrategyNames.c_str()},
    {"gravity_m_s2", field<&EstimatorOptions::gravity_m_s2>, "|g| [m/s^2]"},
    {"window_s", field<&EstimatorOptions::window_s>, "out-of-sequence window [s]"},
    {"pose_output_rate_hz", field<&EstimatorOptions::pose_output_rate_hz>, "POSE rate, 0 = every IMU step [Hz]"},
    {"anchors_output_rate_hz", field<&EstimatorOptions::anchors_output_rate_hz>, "ANCHORS rate (data time) [Hz]"},
    {"status_rate_hz", field<&EstimatorOptions::status_rate_hz>, "ESTIMATOR_STATUS rate (data time) [Hz]"},
    {"imu.acc_noise_density", field<&EstimatorOptions::imu, &ImuNoiseOptions::acc_noise_density>, "[m/s^2/sqrt(Hz)]"},
    {"imu.gyro_noise_density", field<&EstimatorOptions::imu, &ImuNoiseOptions::gyro_noise_density>, "[rad/s/sqrt(Hz)]"},
    {"imu.acc_bias_rw", field<&EstimatorOptions::imu, &ImuNoiseOptions::acc_bias_rw>, "[m/s^3/sqrt(Hz)]"},
    {"imu.gyro_bias_rw", field<&EstimatorOptions::imu, &ImuNoiseOptions::gyro_bias_rw>, "[rad/s^2/sqrt(Hz)]"},
    {"imu.max_dt_s", field<&EstimatorOptions::imu, &ImuNoiseOptions::max_dt_s>, "longer IMU gaps are counted as imu_gap and inflated [s]"},
    {"imu.gap_readings", field<&EstimatorOptions::imu, &ImuNoiseOptions::gap_readings>, "mean | still | held: in a gap propagate on the low-passed readings, as if the vehicle kept its velocity and attitude, or on the last reading repeated"},
    {"init.duration_s", field<&EstimatorOptions::init, &InitOptions::duration_s>, "landed data before initializing [s]"},
    {"init.min_ranges", field<&EstimatorOptions::init, &InitOptions::min_ranges>, "tag-anchor ranges needed without initial_pose [-]"},
    {"init.sigma_bias_gyro_rad_s", field<&EstimatorOptions::init, &InitOptions::sigma_bias_gyro_rad_s>, "[rad/s]"},
    {"init.sigma_bias_acc_m_s2", field<&EstimatorOptions::init, &InitOptions::sigma_bias_acc_m_s2>, "[m/s^2]"},
    {"init.motion_window_s", field<&EstimatorOptions::init, &InitOptions::motion_window_s>, "in-motion alignment window [s]"},
    {"init.resume_max_age_s", field<&EstimatorOptions::init, &InitOptions::resume_max_age_s>, "a restart resumes from a checkpoint at most this old [s]"},
    {"init.resume_max_outage_s", field<&EstimatorOptions::init, &InitOptions::resume_max_outage_s>, "longer restart outages re-initialize the pose (anchors kept) [s]"},
    {"baro.enabled", field<&EstimatorOptions::baro, &BaroOptions::enabled>, ""},
    {"baro.pressure_sigma_pa", field<&EstimatorOptions::baro, &BaroOptions::pressure_sigma_pa>, "[Pa]"},
    {"baro.bias_rw_m_per_sqrt_s", field<&EstimatorOptions::baro, &BaroOptions::bias_rw_m_per_sqrt_s>, "height bias random walk [m/sqrt(s)]"},
    {"baro.init_bias_sigma_m", field<&EstimatorOptions::baro, &BaroOptions::init_bias_sigma_m>, "bias sigma with a given reference pressure [m]"},
    {"height.enabled", field<&EstimatorOptions::height, &HeightOptions::enabled>, "downward rangefinder (height.csv)"},
    {"height.sigma_m", field<&EstimatorOptions::height, &HeightOptions::sigma_m>, "range noise sigma [m]"},
    {"height.bias_rw_m_per_sqrt_s", field<&EstimatorOptions::height, &HeightOptions::bias_rw_m_per_sqrt_s>, "bias random walk [m/sqrt(s)]"},
    {"height.init_bias_sigma_m", field<&EstimatorOptions::height, &HeightOptions::init_bias_sigma_m>, "prior sigma of the bias around 0 [m]"},
    {"height.min_range_m", field<&EstimatorOptions::height, &HeightOptions::min_range_m>, "shorter readings are not used (clamped at the sensor's minimum) [m]"},
    {"carried_height.enabled", field<&EstimatorOptions::carried_height, &CarriedHeightOptions::enabled>, "used when setup.yaml has carried_height (hand-held rig)"},
    {"carried_height.sigma_m", field<&EstimatorOptions::carried_height, &CarriedHeightOptions::sigma_m>, "sigma of one reading (gait bob and sway) [m]"},
    {"carried_height.bias_rw_m_per_sqrt_s", field<&EstimatorOptions::carried_height, &CarriedHeightOptions::bias_rw_m_per_sqrt_s>, "random walk of the carrying height [m/sqrt(s)]"},
    {"uwb.enabled", field<&EstimatorOptions::uwb, &UwbOptions::enabled>, ""},
    {"uwb.sigma_range_m", field<&EstimatorOptions::uwb, &UwbOptions::sigma_range_m>, "fallback range sigma [m]"},
    {"uwb.gate_probability", field<&EstimatorOptions::uwb, &UwbOptions::gate_probability>, "chi^2 gate, 0 = off [-]"},
    {"uwb.huber_k", field<&EstimatorOptions::uwb, &UwbOptions::huber_k>, "Huber threshold of the range update in innovation sigmas, 0 = off [-]"},
    {"uwb.use_corrected_range", field<&EstimatorOptions::uwb, &UwbOptions::use_corrected_range>, "fuse range_corr instead of range_raw (one more than 1 m from it is bad input)"},
    {"uwb.max_range_m", field<&EstimatorOptions::uwb, &UwbOptions::max_range_m>, "longer ranges are bad input [m]"},
    {"uwb.estimate_tag_biases", field<&EstimatorOptions::uwb, &UwbOptions::estimate_tag_biases>, "estimate tag-anchor gamma (setup anchors, sigma_gamma > 0) as states"},
    {"uwb.uncalibrated_gamma_sigma_m", field<&EstimatorOptions::uwb, &UwbOptions::uncalibrated_gamma_sigma_m>, "1 sigma of a tag-anchor pair's own constant bias when setup.yaml does not list the pair (around the tag's common offset; setup noise.sigma_gamma overrides); 0 = such a pair is exact [m]"},
    {"uwb.estimate_anchor_biases", field<&EstimatorOptions::uwb, &UwbOptions::estimate_anchor_biases>, "estimate a calibrated anchor's gamma (ANCHOR_INIT, sigma_gamma > 0) as states of its instance"},
    {"uwb.estimate_setup_anchor_biases", field<&EstimatorOptions::uwb, &UwbOptions::estimate_setup_anchor_biases>, "the same for known-but-uncertain setup anchors (towards exact and smaller-id uncertain anchors)"},
    {"uwb.fuse_calibrated_anchor_pairs", field<&EstimatorOptions::uwb, &UwbOptions::fuse_calibrated_anchor_pairs>, "fuse ranges between two calibrated anchors (their correlated calibration errors are not known)"},
    {"uwb.dah_fuse_estimated_anchor_pairs", field<&EstimatorOptions::uwb, &UwbOptions::dah_fuse_estimated_anchor_pairs>, "dah only: fuse ranges between two estimated anchors (overconfident, see docs)"},
    {"uwb.dah_joint_anchors", field<&EstimatorOptions::uwb, &UwbOptions::dah_joint_anchors>, "dah only: anchors updated jointly: none | batch (added together, e.g. by a re-run) | all"},
    {"uwb.nlos_fraction", field<&EstimatorOptions::uwb, &UwbOptions::nlos_fraction>, "prior probability that a range carries an NLOS excess (the update after the gate is the mixture's collapsed posterior), 0 = Gaussian only [-]"},
    {"uwb.range_error_correlation_s", field<&EstimatorOptions::uwb, &UwbOptions::range_error_correlation_s>, "correlation time of a pair's range error: the update weighs R x (1 + rho)/(1 - rho), rho = exp(-dt/tau), dt since the pair's previous range (the gate judges R); 0 = white [s]"},
    {"uwb.reentry_gap_s", field<&EstimatorOptions::uwb, &UwbOptions::reentry_gap_s>, "no tag range accepted for this long: hold and cross-check the next ones, 0 = off [s]"},
    {"zupt.enabled", field<&EstimatorOptions::zupt, &ZuptOptions::enabled>, ""},
    {"zupt.sigma_vel_m_s", field<&EstimatorOptions::zupt, &ZuptOptions::sigma_vel_m_s>, "sigma of v = 0 [m/s]"},
    {"zupt.detect_stillness", field<&EstimatorOptions::zupt, &ZuptOptions::detect_stillness>, "without FLIGHT_STATE: ZUPT while the IMU shows rest"},
    {"zupt.stillness_sigma_vel_m_s", field<&EstimatorOptions::zupt, &ZuptOptions::stillness_sigma_vel_m_s>, "sigma of v = 0 when only IMU stillness says rest (a smooth hover drifts) [m/s]"},
    {"health.window_s", field<&EstimatorOptions::health, &HealthOptions::window_s>, "innovation statistics window [s]"},
    {"process_noise.adapt", field<&EstimatorOptions::process_noise, &ProcessNoiseAdaptOptions::enabled>, "scale the IMU noise densities to the range innovations"},
    {"recovery.enabled", field<&EstimatorOptions::recovery, &RecoveryOptions::enabled>, "re-initialize from ranges and IMU when lost"},
    {"flight_volume.enabled", field<&EstimatorOptions::flight_volume, &FlightVolumeOptions::enabled>, "use setup flight_volume: against the mirror image of coplanar known anchors on its walls or ceiling, and to drop initial fits outside it"},
    {"time.max_offset_s", field<&EstimatorOptions::time, &TimeGuardOptions::max_offset_s>, "an input stamped farther than this from the current (newest) time is refused and counted [s]"},
    {"refine.rerun_on_anchor_join", field<&EstimatorOptions::refine, &RefineOptions::rerun_on_anchor_join>, "on ANCHOR_INIT re-run from the oldest stored input with the calibrated anchors uncertain from there"},
    {"refine.max_history_s", field<&EstimatorOptions::refine, &RefineOptions::max_history_s>, "inputs kept for re-runs (about 260 B each, S2: 360 inputs/s); older ones are dropped in eighths, counted [s]"},
    {"fixed_lag.lag_s", field<&EstimatorOptions::fixed_lag, &FixedLagOptions::lag_s>, "fixed-lag smoothed poses beside the filter's (POSE_SMOOTHED, estimate_smoothed.csv), each holding at least this much data after it; 0 = none [s]"},
};

/// The model parameters (docs/configuration.md, "Model parameters"): fixed in code with their
/// reasons in estimator_options.h, set only through the C++ API (tests, tools). A file that still
/// sets one is refused with this list's key, so an old config fails loudly instead of being ignored.
const Field kModelParameters[] = {
    {"joseph_form", field<&EstimatorOptions::joseph_form>, "Joseph covariance update (false: P - K S K^T, symmetrized)"},
    {"imu.hold_for_next_sample", field<&EstimatorOptions::imu, &ImuNoiseOptions::hold_for_next_sample>, "a measurement after the last IMU sample waits for the next one and is propagated on readings interpolated between the two (false: extrapolated at once)"},
    {"imu.extrapolate_max_period_s", field<&EstimatorOptions::imu, &ImuNoiseOptions::extrapolate_max_period_s>, "readings between samples extrapolated when the last two are at most this far apart, else held; 0 = always held [s]"},
    {"imu.gap_sigma_acc_m_s2", field<&EstimatorOptions::imu, &ImuNoiseOptions::gap_sigma_acc_m_s2>, "error of the readings a gap is propagated on [m/s^2/sqrt(s)]"},
    {"imu.gap_sigma_gyro_rad_s", field<&EstimatorOptions::imu, &ImuNoiseOptions::gap_sigma_gyro_rad_s>, "error of the readings a gap is propagated on [rad/s/sqrt(s)]"},
    {"imu.gap_mean_time_constant_s", field<&EstimatorOptions::imu, &ImuNoiseOptions::gap_mean_time_constant_s>, "low-pass of the readings for gap_readings mean [s]"},
    {"init.assume_landed_without_flight_state", field<&EstimatorOptions::init, &InitOptions::assume_landed_without_flight_state>, "no FLIGHT_STATE received yet: treat as landed (else IMU stillness decides)"},
    {"init.sigma_v_m_s", field<&EstimatorOptions::init, &InitOptions::sigma_v_m_s>, "[m/s]"},
    {"init.sigma_roll_pitch_deg", field<&EstimatorOptions::init, &InitOptions::sigma_roll_pitch_deg>, "[deg]"},
    {"init.range_init_min_sigma_p_m", field<&EstimatorOptions::init, &InitOptions::range_init_min_sigma_p_m>, "floor of position sigma from ranges [m]"},
    {"init.range_init_sigma_yaw_deg", field<&EstimatorOptions::init, &InitOptions::range_init_sigma_yaw_deg>, "yaw sigma when initialized from ranges [deg]"},
    {"init.range_init_outlier_m", field<&EstimatorOptions::init, &InitOptions::range_init_outlier_m>, "init range residual treated as outlier [m]"},
    {"init.static_max_sigma_yaw_deg", field<&EstimatorOptions::init, &InitOptions::static_max_sigma_yaw_deg>, "static range fit refused above [deg]"},
    {"init.ambiguity_chi2", field<&EstimatorOptions::init, &InitOptions::ambiguity_chi2>, "second fit minimum within this cost: ambiguous, refused [-]"},
    {"init.settle_max_s", field<&EstimatorOptions::init, &InitOptions::settle_max_s>, "before the initialization, inputs wait until every stream has passed them, at most this long [s]"},
    {"init.gravity_early_check_nis_ratio", field<&EstimatorOptions::init, &InitOptions::gravity_early_check_nis_ratio>, "median range NIS over its expected value that runs the gravity-direction check before its time, once, 0 = never [-]"},
    {"init.motion_max_window_s", field<&EstimatorOptions::init, &InitOptions::motion_max_window_s>, "in-motion alignment: longest window when ranges are sparse (count-based) [s]"},
    {"init.motion_min_span_s", field<&EstimatorOptions::init, &InitOptions::motion_min_span_s>, "in-motion alignment shortest window [s]"},
    {"init.motion_min_ranges", field<&EstimatorOptions::init, &InitOptions::motion_min_ranges>, "in-motion alignment ranges needed [-]"},
    {"init.motion_max_sigma_yaw_deg", field<&EstimatorOptions::init, &InitOptions::motion_max_sigma_yaw_deg>, "in-motion alignment refused above [deg]"},
    {"init.motion_max_sigma_p_m", field<&EstimatorOptions::init, &InitOptions::motion_max_sigma_p_m>, "in-motion alignment refused above [m]"},
    {"init.motion_relinearize_rad", field<&EstimatorOptions::init, &InitOptions::motion_relinearize_rad>, "in-motion alignment: re-integrate at the fitted gyro bias when it turns the attitude more than this over the window, 0 = never [rad]"},
    {"init.motion_use_baro", field<&EstimatorOptions::init, &InitOptions::motion_use_baro>, "baro heights (setup reference pressure given) constrain the in-motion alignment's height"},
    {"init.resume_max_acc_m_s2", field<&EstimatorOptions::init, &InitOptions::resume_max_acc_m_s2>, "largest acceleration during a restart's outage [m/s^2]"},
    {"init.resume_max_rate_deg_s", field<&EstimatorOptions::init, &InitOptions::resume_max_rate_deg_s>, "largest rotation rate during a restart's outage [deg/s]"},
    {"baro.gate_probability", field<&EstimatorOptions::baro, &BaroOptions::gate_probability>, "chi^2 gate, 0 = off [-]"},
    {"height.gate_probability", field<&EstimatorOptions::height, &HeightOptions::gate_probability>, "chi^2 gate, 0 = off [-]"},
    {"height.tilt_correction", field<&EstimatorOptions::height, &HeightOptions::tilt_correction>, "h = p_z / cos(tilt) (false: h = p_z)"},
    {"height.max_tilt_deg", field<&EstimatorOptions::height, &HeightOptions::max_tilt_deg>, "not used while tilted more [deg]"},
    {"height.align_rate_hz", field<&EstimatorOptions::height, &HeightOptions::align_rate_hz>, "rate fed to the in-motion alignment, 0 = not used there [Hz]"},
    {"carried_height.rate_hz", field<&EstimatorOptions::carried_height, &CarriedHeightOptions::rate_hz>, "pseudo-readings per second of IMU time [Hz]"},
    {"uwb.huber_max_prior_ratio", field<&EstimatorOptions::uwb, &UwbOptions::huber_max_prior_ratio>, "Huber weighting only while H P H^T / R of the range is at most this [-]"},
    {"uwb.anchor_bias_joint_covariance", field<&EstimatorOptions::uwb, &UwbOptions::anchor_bias_joint_covariance>, "initialize them with the calibration's joint covariance of position and gamma"},
    {"uwb.dah_joint_tag_biases", field<&EstimatorOptions::uwb, &UwbOptions::dah_joint_tag_biases>, "dah only: the tags' gamma instances join the anchors' joint set (merges the batches into one)"},
    {"uwb.dah_joint_imu", field<&EstimatorOptions::uwb, &UwbOptions::dah_joint_imu>, "dah only: the IMU (with the baro and height biases) joins that set too (every pose update also corrects its anchors)"},
    {"uwb.dah_joint_max_anchors", field<&EstimatorOptions::uwb, &UwbOptions::dah_joint_max_anchors>, "dah only: most estimated anchors in a joint set, the most refined leave first, 0 = no bound [-]"},
    {"uwb.uncalibrated_common_gamma_sigma_m", field<&EstimatorOptions::uwb, &UwbOptions::uncalibrated_common_gamma_sigma_m>, "1 sigma of the offset common to an unlisted tag's pairs [m]"},
    {"uwb.nlos_min_excess_m", field<&EstimatorOptions::uwb, &UwbOptions::nlos_min_excess_m>, "smallest NLOS excess b0 [m]"},
    {"uwb.nlos_mean_excess_m", field<&EstimatorOptions::uwb, &UwbOptions::nlos_mean_excess_m>, "mean NLOS excess beyond b0 [m]"},
    {"uwb.clock_offset_sigma_s", field<&EstimatorOptions::uwb, &UwbOptions::clock_offset_sigma_s>, "prior sigma of the UWB stamps' delay against the IMU clock when setup.yaml uwb_clock.sigma_s gives none (setup.yaml is where a user states it; 0 there = known exactly) [s]"},
    {"uwb.clock_offset_rw_s_per_sqrt_s", field<&EstimatorOptions::uwb, &UwbOptions::clock_offset_rw_s_per_sqrt_s>, "random walk of that delay [s/sqrt(s)]"},
    {"uwb.reentry_hold_s", field<&EstimatorOptions::uwb, &UwbOptions::reentry_hold_s>, "longest hold after a gap, at most window_s [s]"},
    {"uwb.reentry_min_ranges", field<&EstimatorOptions::uwb, &UwbOptions::reentry_min_ranges>, "held ranges needed to test them against each other [-]"},
    {"uwb.reentry_min_anchors", field<&EstimatorOptions::uwb, &UwbOptions::reentry_min_anchors>, "distinct anchors among them [-]"},
    {"uwb.reentry_gate_probability", field<&EstimatorOptions::uwb, &UwbOptions::reentry_gate_probability>, "leave-one-out chi^2 gate of a held range [-]"},
    {"zupt.rate_hz", field<&EstimatorOptions::zupt, &ZuptOptions::rate_hz>, "pseudo-measurement rate while landed [Hz]"},
    {"zupt.sigma_acc_m_s2", field<&EstimatorOptions::zupt, &ZuptOptions::sigma_acc_m_s2>, "sigma of a = 0 [m/s^2]"},
    {"zupt.sigma_gyro_rad_s", field<&EstimatorOptions::zupt, &ZuptOptions::sigma_gyro_rad_s>, "rest rotation allowed while landed; the omega row fuses the mean gyro since the last ZUPT with sigma^2 = this^2 + gyro_noise_density^2/T [rad/s]"},
    {"zupt.stillness_gate_probability", field<&EstimatorOptions::zupt, &ZuptOptions::stillness_gate_probability>, "chi^2 gate of those ZUPTs [-]"},
    {"zupt.stillness_sigma_gyro_rad_s", field<&EstimatorOptions::zupt, &ZuptOptions::stillness_sigma_gyro_rad_s>, "sigma of omega = 0 and of the initial gyro bias on stillness alone [rad/s]"},
    {"health.min_ranges", field<&EstimatorOptions::health, &HealthOptions::min_ranges>, "ranges in the window before gating can mean lost [-]"},
    {"health.min_anchors", field<&EstimatorOptions::health, &HealthOptions::min_anchors>, "anchors gated alike before it means lost [-]"},
    {"health.degraded_gated_fraction", field<&EstimatorOptions::health, &HealthOptions::degraded_gated_fraction>, "[-]"},
    {"health.lost_gated_fraction", field<&EstimatorOptions::health, &HealthOptions::lost_gated_fraction>, "[-]"},
    {"health.degraded_mean_nis", field<&EstimatorOptions::health, &HealthOptions::degraded_mean_nis>, "mean NIS of accepted ranges, 1 if consistent [-]"},
    {"health.degraded_no_aiding_s", field<&EstimatorOptions::health, &HealthOptions::degraded_no_aiding_s>, "no accepted range for this long: degraded [s]"},
    {"health.lost_no_aiding_s", field<&EstimatorOptions::health, &HealthOptions::lost_no_aiding_s>, "no accepted range for this long: lost [s]"},
    {"health.lost_sigma_p_m", field<&EstimatorOptions::health, &HealthOptions::lost_sigma_p_m>, "largest position sigma beyond which the pose is lost [m]"},
    {"health.hold_s", field<&EstimatorOptions::health, &HealthOptions::hold_s>, "a better health must hold this long [s]"},
    {"process_noise.batch", field<&EstimatorOptions::process_noise, &ProcessNoiseAdaptOptions::batch>, "tag-anchor ranges per decision [-]"},
    {"process_noise.upper_ratio", field<&EstimatorOptions::process_noise, &ProcessNoiseAdaptOptions::upper_ratio>, "median NIS ratio above which the scale grows [-]"},
    {"process_noise.lower_ratio", field<&EstimatorOptions::process_noise, &ProcessNoiseAdaptOptions::lower_ratio>, "median NIS ratio below which the scale shrinks [-]"},
    {"process_noise.max_grow", field<&EstimatorOptions::process_noise, &ProcessNoiseAdaptOptions::max_grow>, "largest growth of the scale per decision (factor) [-]"},
    {"process_noise.max_shrink", field<&EstimatorOptions::process_noise, &ProcessNoiseAdaptOptions::max_shrink>, "largest shrink of the scale per decision (factor) [-]"},
    {"process_noise.max_scale", field<&EstimatorOptions::process_noise, &ProcessNoiseAdaptOptions::max_scale>, "largest variance scale [-]"},
    {"process_noise.max_prior_ratio", field<&EstimatorOptions::process_noise, &ProcessNoiseAdaptOptions::max_prior_ratio>, "no growth while the median predicted range variance HPH'/R exceeds this [-]"},
    {"recovery.retry_s", field<&EstimatorOptions::recovery, &RecoveryOptions::retry_s>, "between two attempts while lost or degraded [s]"},
    {"recovery.degraded_disagreement_chi2", field<&EstimatorOptions::recovery, &RecoveryOptions::degraded_disagreement_chi2>, "degraded: re-initialize when the aligned pose disagrees beyond this chi^2 (4 dof), 0 = off [-]"},
    {"recovery.after_gap_check_min_s", field<&EstimatorOptions::recovery, &RecoveryOptions::after_gap_check_min_s>, "after an IMU gap this long, compare the aligned pose with the filter as while degraded, for init.motion_window_s, 0 = off [s]"},
    {"flight_volume.mirror_margin_m", field<&EstimatorOptions::flight_volume, &FlightVolumeOptions::mirror_margin_m>, "an estimate this far outside whose mirror image is inside is reflected [m]"},
    {"flight_volume.side_constraint_rate_hz", field<&EstimatorOptions::flight_volume, &FlightVolumeOptions::side_constraint_rate_hz>, "truncate the position to the volume's side of the anchors' plane at most this often, 0 = off [Hz]"},
    {"flight_volume.candidate_margin_m", field<&EstimatorOptions::flight_volume, &FlightVolumeOptions::candidate_margin_m>, "initialization: a fit ending farther outside is no candidate [m]"},
    {"time.rebase_after", field<&EstimatorOptions::time, &TimeGuardOptions::rebase_after>, "this many consecutive refused inputs agreeing among themselves move the clock (a real jump) [-]"},
    {"refine.rerun_prior_sigma_m", field<&EstimatorOptions::refine, &RefineOptions::rerun_prior_sigma_m>, "position sigma per axis of a calibrated anchor in a re-run, around its calibration [m]"},
    {"refine.rerun_gamma_sigma_m", field<&EstimatorOptions::refine, &RefineOptions::rerun_gamma_sigma_m>, "sigma of its gamma in a re-run [m]"},
    {"refine.rerun_gamma_from_calibration", field<&EstimatorOptions::refine, &RefineOptions::rerun_gamma_from_calibration>, "gamma means of a re-run: the calibration's (true) or the calibrator's prior mean 0 (false)"},
    {"refine.rerun_with_dah", field<&EstimatorOptions::refine, &RefineOptions::rerun_with_dah>, "strategy dah too (with its joint sets, uwb.dah_joint_anchors; see docs)"},
    {"refine.rerun_mode", field<&EstimatorOptions::refine, &RefineOptions::rerun_mode>, "auto | sync | async: re-run inline, or on a worker while the node keeps publishing; auto = async in the LCM process, sync in replays"},
    {"fixed_lag.period_s", field<&EstimatorOptions::fixed_lag, &FixedLagOptions::period_s>, "data time between two backward passes of the fixed-lag smoother [s]"},
};

/// Visits every option as (dotted key, field, unit/comment).
template <typename Opt, typename Visitor>
void forEachField(Opt& o, Visitor&& v) {
  forEachOption(o, kFields, v);
}

std::vector<std::string> splitKey(const std::string& key) {
  std::vector<std::string> parts;
  std::stringstream ss(key);
  std::string p;
  while (std::getline(ss, p, '.')) parts.push_back(p);
  return parts;
}

std::string formatValue(const std::string& v) { return v; }
std::string formatValue(bool v) { return v ? "true" : "false"; }
std::string formatValue(int v) { return std::to_string(v); }
std::string formatValue(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  std::string s = os.str();
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

}  // namespace

EstimatorOptions EstimatorOptions::fromYaml(const std::string& path) {
  // The one rule of common/yaml_options.h: unknown keys and bad values are errors naming the file
  // and the key; a missing key keeps its default (the defaults are the shipped file).
  YamlOptions yaml(YamlOptions::loadFile(path), path);
  for (const Field& f : kModelParameters) {
    if (yaml.has(f.key)) {
      yaml.fail(f.key, "is a model parameter since 2026-12-05, fixed in code with its reason, not an option any "
                       "more (docs/configuration.md, \"Model parameters\"); remove it from the file");
    }
  }
  // The profile first: its groups are the defaults the rest of the file overrides.
  std::string profile = EstimatorOptions{}.profile;
  yaml.read("profile", profile);
  if (!profileListed(profile)) yaml.fail("profile", "must be auto, drone or handheld, got '" + profile + "'");
  return readOptionsList<EstimatorOptions>(yaml, [](auto& o, auto&& v) { forEachField(o, v); },
                                           forProfile(profile));
}

bool EstimatorOptions::profileListed(const std::string& name) {
  return name == "auto" || name == "drone" || name == "handheld";
}

EstimatorOptions EstimatorOptions::forProfile(const std::string& name) {
  EstimatorOptions o;
  o.profile = name;
  if (name == "drone") {
    // Nobody carries a drone: the carried-height pseudo-readings are off even when a setup file
    // written for a hand-held rig has `carried_height`.
    o.carried_height.enabled = false;
  } else if (name == "handheld") {
    // A rig carried by a walker: a downward rangefinder on it reads the walker's gait, not a height
    // above a floor the height model can use (its bias instance would chase the bob), so it is off.
    o.height.enabled = false;
  }
  return o;
}

void EstimatorOptions::validate() const {
  auto need = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("invalid option: " + what);
  };
  need(strategyListed(strategy), "strategy must be one of " + strategyNames(", "));
  need(profileListed(profile), "profile must be auto, drone or handheld");
  need(gravity_m_s2 > 0.0, "gravity_m_s2 > 0");
  need(uwb.dah_joint_anchors == "none" || uwb.dah_joint_anchors == "batch" || uwb.dah_joint_anchors == "all",
       "uwb.dah_joint_anchors must be none, batch or all");
  need(uwb.dah_joint_max_anchors >= 0, "uwb.dah_joint_max_anchors >= 0 (0: no bound)");
  need(window_s >= 0.0, "window_s >= 0");
  need(uwb.reentry_gap_s >= 0.0 && (uwb.reentry_gap_s == 0.0 || (uwb.reentry_hold_s > 0.0 && uwb.reentry_hold_s <= window_s)),
       "uwb.reentry_gap_s >= 0; with a gap, 0 < uwb.reentry_hold_s <= window_s");
  need(uwb.reentry_min_ranges >= 2 && uwb.reentry_min_anchors >= 2 && uwb.reentry_gate_probability > 0.0 &&
           uwb.reentry_gate_probability < 1.0,
       "uwb.reentry_min_ranges >= 2, uwb.reentry_min_anchors >= 2, 0 < uwb.reentry_gate_probability < 1");
  need(pose_output_rate_hz >= 0.0 && anchors_output_rate_hz > 0.0 && status_rate_hz > 0.0, "output rates");
  need(imu.acc_noise_density > 0 && imu.gyro_noise_density > 0 && imu.acc_bias_rw >= 0 && imu.gyro_bias_rw >= 0,
       "imu noise densities > 0");
  need(imu.max_dt_s > 0.0, "imu.max_dt_s > 0");
  need(imu.extrapolate_max_period_s >= 0.0, "imu.extrapolate_max_period_s >= 0");
  need(imu.gap_sigma_acc_m_s2 >= 0.0 && imu.gap_sigma_gyro_rad_s >= 0.0, "imu.gap_sigma_* >= 0");
  need(imu.gap_readings == "mean" || imu.gap_readings == "still" || imu.gap_readings == "held",
       "imu.gap_readings must be mean, still or held");
  need(imu.gap_mean_time_constant_s > 0.0, "imu.gap_mean_time_constant_s > 0");
  need(init.static_max_sigma_yaw_deg > 0 && init.ambiguity_chi2 > 0 && init.motion_window_s >= init.motion_min_span_s &&
           init.motion_min_span_s > 0 && init.motion_min_ranges >= 8 && init.motion_max_sigma_yaw_deg > 0 &&
           init.motion_max_sigma_p_m > 0 && init.resume_max_age_s >= 0 && init.resume_max_acc_m_s2 >= 0 &&
           init.resume_max_rate_deg_s >= 0 && init.resume_max_outage_s >= 0,
       "init.motion_* (window >= min span > 0, min_ranges >= 8, sigmas > 0)");
  need(init.motion_relinearize_rad >= 0 && init.motion_relinearize_rad < M_PI, "init.motion_relinearize_rad in [0, pi)");
  need(init.gravity_early_check_nis_ratio >= 0, "init.gravity_early_check_nis_ratio >= 0");
  need(init.settle_max_s >= 0, "init.settle_max_s >= 0");
  need(health.window_s > 0 && health.min_ranges >= 1 && health.min_anchors >= 1 &&
           health.degraded_gated_fraction > 0 && health.degraded_gated_fraction <= health.lost_gated_fraction &&
           health.lost_gated_fraction <= 1 && health.degraded_mean_nis > 0 && health.degraded_no_aiding_s > 0 &&
           health.lost_no_aiding_s >= health.degraded_no_aiding_s && health.lost_sigma_p_m > 0 && health.hold_s >= 0,
       "health.* (0 < degraded <= lost fractions <= 1, positive times)");
  need(recovery.retry_s > 0 && recovery.degraded_disagreement_chi2 >= 0 && recovery.after_gap_check_min_s >= 0,
       "recovery.retry_s > 0, recovery.degraded_disagreement_chi2 >= 0, recovery.after_gap_check_min_s >= 0");
  need(flight_volume.mirror_margin_m >= 0 && flight_volume.side_constraint_rate_hz >= 0 &&
           flight_volume.candidate_margin_m >= 0,
       "flight_volume: mirror_margin_m >= 0, side_constraint_rate_hz >= 0, candidate_margin_m >= 0");
  need(zupt.stillness_gate_probability > 0 && zupt.stillness_gate_probability < 1,
       "zupt.stillness_gate_probability in (0, 1)");
  need(init.duration_s >= 0.0 && init.min_ranges >= 4, "init.duration_s >= 0, init.min_ranges >= 4");
  need(init.sigma_v_m_s > 0 && init.sigma_roll_pitch_deg > 0 && init.sigma_bias_gyro_rad_s > 0 &&
           init.sigma_bias_acc_m_s2 > 0 && init.range_init_min_sigma_p_m > 0 && init.range_init_sigma_yaw_deg > 0 &&
           init.range_init_outlier_m > 0,
       "init sigmas > 0");
  need(baro.pressure_sigma_pa > 0 && baro.bias_rw_m_per_sqrt_s >= 0 && baro.init_bias_sigma_m > 0, "baro sigmas");
  need(baro.gate_probability >= 0 && baro.gate_probability < 1, "baro.gate_probability in [0, 1)");
  need(height.sigma_m > 0 && height.bias_rw_m_per_sqrt_s >= 0 && height.init_bias_sigma_m > 0 &&
           height.min_range_m >= 0 && height.max_tilt_deg > 0 && height.max_tilt_deg < 90 && height.align_rate_hz >= 0,
       "height: sigma_m > 0, bias_rw >= 0, init_bias_sigma_m > 0, min_range_m >= 0, max_tilt_deg in (0, 90), align_rate_hz >= 0");
  need(height.gate_probability >= 0 && height.gate_probability < 1, "height.gate_probability in [0, 1)");
  need(carried_height.rate_hz > 0 && carried_height.sigma_m > 0 && carried_height.bias_rw_m_per_sqrt_s >= 0,
       "carried_height: rate_hz > 0, sigma_m > 0, bias_rw_m_per_sqrt_s >= 0");
  need(init.motion_max_window_s >= init.motion_window_s, "init.motion_max_window_s >= init.motion_window_s");
  need(uwb.sigma_range_m > 0 && uwb.max_range_m > 0, "uwb.sigma_range_m > 0, uwb.max_range_m > 0");
  need(uwb.gate_probability >= 0 && uwb.gate_probability < 1, "uwb.gate_probability in [0, 1)");
  need(uwb.huber_k >= 0 && uwb.huber_max_prior_ratio >= 0, "uwb.huber_k >= 0, uwb.huber_max_prior_ratio >= 0");
  need(uwb.uncalibrated_gamma_sigma_m >= 0 && uwb.uncalibrated_gamma_sigma_m <= 10 &&
           uwb.uncalibrated_common_gamma_sigma_m >= 0 && uwb.uncalibrated_common_gamma_sigma_m <= 10,
       "uwb.uncalibrated_gamma_sigma_m and uwb.uncalibrated_common_gamma_sigma_m in [0, 10] [m]");
  need(uwb.range_error_correlation_s >= 0 && uwb.range_error_correlation_s <= 60,
       "uwb.range_error_correlation_s in [0, 60] [s]");
  need(uwb.clock_offset_sigma_s >= 0 && uwb.clock_offset_sigma_s <= 1 && uwb.clock_offset_rw_s_per_sqrt_s >= 0 &&
           uwb.clock_offset_rw_s_per_sqrt_s <= 0.1,
       "uwb.clock_offset_sigma_s in [0, 1] [s], uwb.clock_offset_rw_s_per_sqrt_s in [0, 0.1] [s/sqrt(s)]");
  need(uwb.nlos_fraction >= 0 && uwb.nlos_fraction < 1 && uwb.nlos_min_excess_m >= 0 && uwb.nlos_mean_excess_m > 0,
       "uwb.nlos_fraction in [0, 1), uwb.nlos_min_excess_m >= 0, uwb.nlos_mean_excess_m > 0");
  need(process_noise.batch >= 5 && process_noise.upper_ratio > 1.0 && process_noise.lower_ratio > 0.0 &&
           process_noise.lower_ratio < 1.0 && process_noise.max_grow > 1.0 && process_noise.max_shrink > 1.0 &&
           process_noise.max_scale >= 1.0 && process_noise.max_prior_ratio > 0.0,
       "process_noise: batch >= 5, lower_ratio in (0, 1), upper_ratio > 1, max_grow > 1, max_shrink > 1, max_scale >= 1, max_prior_ratio > 0");
  need(time.max_offset_s >= window_s && time.max_offset_s <= kMaxTimeSeconds && time.rebase_after >= 1,
       "time.max_offset_s >= window_s, time.rebase_after >= 1");
  need(refine.max_history_s >= window_s && refine.rerun_prior_sigma_m > 0 && refine.rerun_gamma_sigma_m > 0,
       "refine.max_history_s >= window_s, refine.rerun_prior_sigma_m > 0, refine.rerun_gamma_sigma_m > 0");
  need(refine.rerun_mode == "auto" || refine.rerun_mode == "sync" || refine.rerun_mode == "async",
       "refine.rerun_mode must be auto, sync or async");
  // A pass shorter than 0.05 s would start at nearly every propagation and finish the previous one
  // before the POSE (FixedLagSmoother::startPass).
  need(fixed_lag.lag_s >= 0.0 && fixed_lag.lag_s <= 60.0 && fixed_lag.period_s >= 0.05 && fixed_lag.period_s <= 10.0,
       "fixed_lag.lag_s in [0, 60] and fixed_lag.period_s in [0.05, 10]");
  need(zupt.rate_hz > 0 && zupt.sigma_acc_m_s2 > 0 && zupt.sigma_gyro_rad_s > 0 && zupt.sigma_vel_m_s > 0 &&
           zupt.stillness_sigma_vel_m_s > 0 && zupt.stillness_sigma_gyro_rad_s > 0,
       "zupt rate and sigmas > 0");
}

void EstimatorOptions::applySetupNoise(const NoiseFigures& n) {
  if (n.sigma_gamma_m) uwb.uncalibrated_gamma_sigma_m = *n.sigma_gamma_m;
  if (n.range_correlation_time_s) uwb.range_error_correlation_s = *n.range_correlation_time_s;
  if (n.imu_acc_noise_density) imu.acc_noise_density = *n.imu_acc_noise_density;
  if (n.imu_gyro_noise_density) imu.gyro_noise_density = *n.imu_gyro_noise_density;
  if (n.imu_acc_bias_rw) imu.acc_bias_rw = *n.imu_acc_bias_rw;
  if (n.imu_gyro_bias_rw) imu.gyro_bias_rw = *n.imu_gyro_bias_rw;
  if (n.imu_acc_bias_sigma) init.sigma_bias_acc_m_s2 = *n.imu_acc_bias_sigma;
  if (n.imu_gyro_bias_sigma) init.sigma_bias_gyro_rad_s = *n.imu_gyro_bias_sigma;
  if (n.baro_pressure_sigma_pa) baro.pressure_sigma_pa = *n.baro_pressure_sigma_pa;
}

namespace {
/// "section:\n  key: value  # comment" lines of every field of `table`.
template <size_t N>
std::string yamlListing(const EstimatorOptions& o, const Field (&table)[N]) {
  std::ostringstream os;
  std::vector<std::string> open;  // currently open YAML sections
  forEachOption(o, table, [&](const std::string& key, const auto& field, const char* unit) {
    auto parts = splitKey(key);
    const std::string section = parts.size() > 1 ? parts[0] : "";
    if (parts.size() > 1 && (open.empty() || open.back() != section)) {
      os << section << ":\n";
      open = {section};
    } else if (parts.size() == 1) {
      open.clear();
    }
    os << (parts.size() > 1 ? "  " : "") << parts.back() << ": " << formatValue(field);
    if (unit && *unit) os << "  # " << unit;
    os << "\n";
  });
  return os.str();
}
}  // namespace

std::string EstimatorOptions::toString() const { return yamlListing(*this, kFields); }

std::string EstimatorOptions::modelParametersString() const { return yamlListing(*this, kModelParameters); }

}  // namespace meshnav::estimator
