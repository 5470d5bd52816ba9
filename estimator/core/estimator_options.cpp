#include "estimator/core/estimator_options.h"
#include "estimator/core/strategy_list.h"

#include "common/yaml_options.h"


#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace meshnav::estimator {
namespace {

/// forEachField, part: the top-level options and the IMU.
template <typename Opt, typename Visitor>
void forEachGeneralField(Opt& o, Visitor& v) {
  static const std::string strategy_names = strategyNames(" | ");
  v("strategy", o.strategy, strategy_names.c_str());
  v("gravity_m_s2", o.gravity_m_s2, "|g| [m/s^2]");
  v("window_s", o.window_s, "out-of-sequence window [s]");
  v("pose_output_rate_hz", o.pose_output_rate_hz, "POSE rate, 0 = every IMU step [Hz]");
  v("anchors_output_rate_hz", o.anchors_output_rate_hz, "ANCHORS rate (data time) [Hz]");
  v("status_rate_hz", o.status_rate_hz, "ESTIMATOR_STATUS rate (data time) [Hz]");
  v("joseph_form", o.joseph_form, "Joseph covariance update (false: P - K S K^T, symmetrized)");
  v("imu.acc_noise_density", o.imu.acc_noise_density, "[m/s^2/sqrt(Hz)]");
  v("imu.gyro_noise_density", o.imu.gyro_noise_density, "[rad/s/sqrt(Hz)]");
  v("imu.acc_bias_rw", o.imu.acc_bias_rw, "[m/s^3/sqrt(Hz)]");
  v("imu.gyro_bias_rw", o.imu.gyro_bias_rw, "[rad/s^2/sqrt(Hz)]");
  v("imu.max_dt_s", o.imu.max_dt_s, "longer IMU gaps are counted as imu_gap and inflated [s]");
  v("imu.gap_sigma_acc_m_s2", o.imu.gap_sigma_acc_m_s2, "held-reading error during a gap [m/s^2/sqrt(s)]");
  v("imu.gap_sigma_gyro_rad_s", o.imu.gap_sigma_gyro_rad_s, "held-reading error during a gap [rad/s/sqrt(s)]");
}

/// forEachField, part: initialization (static, in motion, resume).
template <typename Opt, typename Visitor>
void forEachInitField(Opt& o, Visitor& v) {
  v("init.duration_s", o.init.duration_s, "landed data before initializing [s]");
  v("init.min_ranges", o.init.min_ranges, "tag-anchor ranges needed without initial_pose [-]");
  v("init.assume_landed_without_flight_state", o.init.assume_landed_without_flight_state,
    "no FLIGHT_STATE received yet: treat as landed (else IMU stillness decides)");
  v("init.sigma_v_m_s", o.init.sigma_v_m_s, "[m/s]");
  v("init.sigma_roll_pitch_deg", o.init.sigma_roll_pitch_deg, "[deg]");
  v("init.sigma_bias_gyro_rad_s", o.init.sigma_bias_gyro_rad_s, "[rad/s]");
  v("init.sigma_bias_acc_m_s2", o.init.sigma_bias_acc_m_s2, "[m/s^2]");
  v("init.range_init_min_sigma_p_m", o.init.range_init_min_sigma_p_m, "floor of position sigma from ranges [m]");
  v("init.range_init_sigma_yaw_deg", o.init.range_init_sigma_yaw_deg, "yaw sigma when initialized from ranges [deg]");
  v("init.range_init_outlier_m", o.init.range_init_outlier_m, "init range residual treated as outlier [m]");
  v("init.static_max_sigma_yaw_deg", o.init.static_max_sigma_yaw_deg, "static range fit refused above [deg]");
  v("init.ambiguity_chi2", o.init.ambiguity_chi2, "second fit minimum within this cost: ambiguous, refused [-]");
  v("init.motion_window_s", o.init.motion_window_s, "in-motion alignment window [s]");
  v("init.motion_max_window_s", o.init.motion_max_window_s,
    "in-motion alignment: longest window when ranges are sparse (count-based) [s]");
  v("init.motion_min_span_s", o.init.motion_min_span_s, "in-motion alignment shortest window [s]");
  v("init.motion_min_ranges", o.init.motion_min_ranges, "in-motion alignment ranges needed [-]");
  v("init.motion_max_sigma_yaw_deg", o.init.motion_max_sigma_yaw_deg, "in-motion alignment refused above [deg]");
  v("init.motion_max_sigma_p_m", o.init.motion_max_sigma_p_m, "in-motion alignment refused above [m]");
  v("init.motion_relinearize_rad", o.init.motion_relinearize_rad,
    "in-motion alignment: re-integrate at the fitted gyro bias when it turns the attitude more than this over the window, 0 = never [rad]");
  v("init.motion_use_baro", o.init.motion_use_baro,
    "baro heights (setup reference pressure given) constrain the in-motion alignment's height");
  v("init.resume_max_age_s", o.init.resume_max_age_s, "a restart resumes from a checkpoint at most this old [s]");
  v("init.resume_max_outage_s", o.init.resume_max_outage_s, "longer restart outages re-initialize the pose (anchors kept) [s]");
  v("init.resume_max_acc_m_s2", o.init.resume_max_acc_m_s2, "largest acceleration during a restart's outage [m/s^2]");
  v("init.resume_max_rate_deg_s", o.init.resume_max_rate_deg_s, "largest rotation rate during a restart's outage [deg/s]");
}

/// forEachField, part: barometer and height sensor.
template <typename Opt, typename Visitor>
void forEachAltitudeField(Opt& o, Visitor& v) {
  v("baro.enabled", o.baro.enabled, "");
  v("baro.pressure_sigma_pa", o.baro.pressure_sigma_pa, "[Pa]");
  v("baro.bias_rw_m_per_sqrt_s", o.baro.bias_rw_m_per_sqrt_s, "height bias random walk [m/sqrt(s)]");
  v("baro.init_bias_sigma_m", o.baro.init_bias_sigma_m, "bias sigma with a given reference pressure [m]");
  v("baro.gate_probability", o.baro.gate_probability, "chi^2 gate, 0 = off [-]");
  v("height.enabled", o.height.enabled, "downward rangefinder (height.csv)");
  v("height.sigma_m", o.height.sigma_m, "range noise sigma [m]");
  v("height.bias_rw_m_per_sqrt_s", o.height.bias_rw_m_per_sqrt_s, "bias random walk [m/sqrt(s)]");
  v("height.init_bias_sigma_m", o.height.init_bias_sigma_m, "prior sigma of the bias around 0 [m]");
  v("height.gate_probability", o.height.gate_probability, "chi^2 gate, 0 = off [-]");
  v("height.min_range_m", o.height.min_range_m, "shorter readings are not used (clamped at the sensor's minimum) [m]");
  v("height.tilt_correction", o.height.tilt_correction, "h = p_z / cos(tilt) (false: h = p_z)");
  v("height.max_tilt_deg", o.height.max_tilt_deg, "not used while tilted more [deg]");
  v("height.align_rate_hz", o.height.align_rate_hz, "rate fed to the in-motion alignment, 0 = not used there [Hz]");
  v("carried_height.enabled", o.carried_height.enabled, "used when setup.yaml has carried_height (hand-held rig)");
  v("carried_height.rate_hz", o.carried_height.rate_hz, "pseudo-readings per second of IMU time [Hz]");
  v("carried_height.sigma_m", o.carried_height.sigma_m, "sigma of one reading (gait bob and sway) [m]");
  v("carried_height.bias_rw_m_per_sqrt_s", o.carried_height.bias_rw_m_per_sqrt_s,
    "random walk of the carrying height [m/sqrt(s)]");
}

/// forEachField, part: UWB ranges.
template <typename Opt, typename Visitor>
void forEachUwbField(Opt& o, Visitor& v) {
  v("uwb.enabled", o.uwb.enabled, "");
  v("uwb.sigma_range_m", o.uwb.sigma_range_m, "fallback range sigma [m]");
  v("uwb.gate_probability", o.uwb.gate_probability, "chi^2 gate, 0 = off [-]");
  v("uwb.use_corrected_range", o.uwb.use_corrected_range, "fuse range_corr instead of range_raw");
  v("uwb.max_range_m", o.uwb.max_range_m, "longer ranges are bad input [m]");
  v("uwb.estimate_tag_biases", o.uwb.estimate_tag_biases, "estimate tag-anchor gamma (setup anchors, sigma_gamma > 0) as states");
  v("uwb.estimate_anchor_biases", o.uwb.estimate_anchor_biases,
    "estimate a calibrated anchor's gamma (ANCHOR_INIT, sigma_gamma > 0) as states of its instance");
  v("uwb.anchor_bias_joint_covariance", o.uwb.anchor_bias_joint_covariance,
    "initialize them with the calibration's joint covariance of position and gamma");
  v("uwb.estimate_setup_anchor_biases", o.uwb.estimate_setup_anchor_biases,
    "the same for known-but-uncertain setup anchors (towards exact and smaller-id uncertain anchors)");
  v("uwb.fuse_calibrated_anchor_pairs", o.uwb.fuse_calibrated_anchor_pairs,
    "fuse ranges between two calibrated anchors (their correlated calibration errors are not known)");
  v("uwb.dah_fuse_estimated_anchor_pairs", o.uwb.dah_fuse_estimated_anchor_pairs,
    "dah only: fuse ranges between two estimated anchors (overconfident, see docs)");
  v("uwb.dah_joint_anchors", o.uwb.dah_joint_anchors,
    "dah only: anchors updated jointly: none | batch (added together, e.g. by a re-run) | all");
  v("uwb.dah_joint_tag_biases", o.uwb.dah_joint_tag_biases,
    "dah only: the tags' gamma instances join the anchors' joint set (merges the batches into one)");
  v("uwb.dah_joint_imu", o.uwb.dah_joint_imu,
    "dah only: the IMU (with the baro and height biases) joins that set too (every pose update also corrects its anchors)");
  v("uwb.dah_joint_max_anchors", o.uwb.dah_joint_max_anchors,
    "dah only: most estimated anchors in a joint set, the most refined leave first, 0 = no bound [-]");
  v("uwb.reentry_gap_s", o.uwb.reentry_gap_s, "no tag range accepted for this long: hold and cross-check the next ones, 0 = off [s]");
  v("uwb.reentry_hold_s", o.uwb.reentry_hold_s, "longest hold after a gap, at most window_s [s]");
  v("uwb.reentry_min_ranges", o.uwb.reentry_min_ranges, "held ranges needed to test them against each other [-]");
  v("uwb.reentry_min_anchors", o.uwb.reentry_min_anchors, "distinct anchors among them [-]");
  v("uwb.reentry_gate_probability", o.uwb.reentry_gate_probability, "leave-one-out chi^2 gate of a held range [-]");
}

/// forEachField, part: zero-velocity updates and the health monitor.
template <typename Opt, typename Visitor>
void forEachRestAndHealthField(Opt& o, Visitor& v) {
  v("zupt.enabled", o.zupt.enabled, "");
  v("zupt.rate_hz", o.zupt.rate_hz, "pseudo-measurement rate while landed [Hz]");
  v("zupt.sigma_acc_m_s2", o.zupt.sigma_acc_m_s2, "sigma of a = 0 [m/s^2]");
  v("zupt.sigma_gyro_rad_s", o.zupt.sigma_gyro_rad_s, "rest rotation allowed while landed; the omega row fuses the mean gyro since the last ZUPT with sigma^2 = this^2 + gyro_noise_density^2/T [rad/s]");
  v("zupt.sigma_vel_m_s", o.zupt.sigma_vel_m_s, "sigma of v = 0 [m/s]");
  v("zupt.detect_stillness", o.zupt.detect_stillness, "without FLIGHT_STATE: ZUPT while the IMU shows rest");
  v("zupt.stillness_gate_probability", o.zupt.stillness_gate_probability, "chi^2 gate of those ZUPTs [-]");
  v("zupt.stillness_sigma_vel_m_s", o.zupt.stillness_sigma_vel_m_s,
    "sigma of v = 0 when only IMU stillness says rest (a smooth hover drifts) [m/s]");
  v("zupt.stillness_sigma_gyro_rad_s", o.zupt.stillness_sigma_gyro_rad_s,
    "sigma of omega = 0 and of the initial gyro bias on stillness alone [rad/s]");
  v("health.window_s", o.health.window_s, "innovation statistics window [s]");
  v("health.min_ranges", o.health.min_ranges, "ranges in the window before gating can mean lost [-]");
  v("health.min_anchors", o.health.min_anchors, "anchors gated alike before it means lost [-]");
  v("health.degraded_gated_fraction", o.health.degraded_gated_fraction, "[-]");
  v("health.lost_gated_fraction", o.health.lost_gated_fraction, "[-]");
  v("health.degraded_mean_nis", o.health.degraded_mean_nis, "mean NIS of accepted ranges, 1 if consistent [-]");
  v("health.degraded_no_aiding_s", o.health.degraded_no_aiding_s, "no accepted range for this long: degraded [s]");
  v("health.lost_no_aiding_s", o.health.lost_no_aiding_s, "no accepted range for this long: lost [s]");
  v("health.lost_sigma_p_m", o.health.lost_sigma_p_m, "largest position sigma beyond which the pose is lost [m]");
  v("health.hold_s", o.health.hold_s, "a better health must hold this long [s]");
}

/// forEachField, part: process-noise adaptation, recovery and the time guard.
template <typename Opt, typename Visitor>
void forEachAdaptationField(Opt& o, Visitor& v) {
  v("process_noise.adapt", o.process_noise.enabled, "scale the IMU noise densities to the range innovations");
  v("process_noise.batch", o.process_noise.batch, "tag-anchor ranges per decision [-]");
  v("process_noise.upper_ratio", o.process_noise.upper_ratio, "median NIS ratio above which the scale grows [-]");
  v("process_noise.lower_ratio", o.process_noise.lower_ratio, "median NIS ratio below which the scale shrinks [-]");
  v("process_noise.max_grow", o.process_noise.max_grow, "largest growth of the scale per decision (factor) [-]");
  v("process_noise.max_shrink", o.process_noise.max_shrink, "largest shrink of the scale per decision (factor) [-]");
  v("process_noise.max_scale", o.process_noise.max_scale, "largest variance scale [-]");
  v("process_noise.max_prior_ratio", o.process_noise.max_prior_ratio,
    "no growth while the median predicted range variance HPH'/R exceeds this [-]");
  v("process_noise.confirm_batches", o.process_noise.confirm_batches,
    "consecutive batches above upper_ratio before the scale grows (by the smallest of their ratios) [-]");
  v("process_noise.grow_at_once_ratio", o.process_noise.grow_at_once_ratio,
    "a batch whose median NIS ratio exceeds this grows the scale without confirmation [-]");
  v("process_noise.min_accepted_fraction", o.process_noise.min_accepted_fraction,
    "median over the accepted ranges while this share of the batch was accepted, else over all [-]");
  v("recovery.enabled", o.recovery.enabled, "re-initialize from ranges and IMU when lost");
  v("recovery.retry_s", o.recovery.retry_s, "between two attempts while lost or degraded [s]");
  v("recovery.degraded_disagreement_chi2", o.recovery.degraded_disagreement_chi2,
    "degraded: re-initialize when the aligned pose disagrees beyond this chi^2 (4 dof), 0 = off [-]");
  v("time.max_offset_s", o.time.max_offset_s,
    "an input stamped farther than this from the current (newest) time is refused and counted [s]");
  v("time.rebase_after", o.time.rebase_after,
    "this many consecutive refused inputs agreeing among themselves move the clock (a real jump) [-]");
}

/// forEachField, part: anchor refinement (the re-run on an anchor join, issue 10).
template <typename Opt, typename Visitor>
void forEachRefineField(Opt& o, Visitor& v) {
  v("refine.rerun_on_anchor_join", o.refine.rerun_on_anchor_join,
    "on ANCHOR_INIT re-run from the oldest stored input with the calibrated anchors uncertain from there");
  v("refine.max_history_s", o.refine.max_history_s,
    "inputs kept for re-runs (about 260 B each, S2: 360 inputs/s); older ones are dropped in eighths, counted [s]");
  v("refine.rerun_prior_sigma_m", o.refine.rerun_prior_sigma_m,
    "position sigma per axis of a calibrated anchor in a re-run, around its calibration [m]");
  v("refine.rerun_gamma_sigma_m", o.refine.rerun_gamma_sigma_m, "sigma of its gamma in a re-run [m]");
  v("refine.rerun_gamma_from_calibration", o.refine.rerun_gamma_from_calibration,
    "gamma means of a re-run: the calibration's (true) or the calibrator's prior mean 0 (false)");
  v("refine.rerun_with_dah", o.refine.rerun_with_dah,
    "strategy dah too (with its joint sets, uwb.dah_joint_anchors; see docs)");
  v("refine.rerun_mode", o.refine.rerun_mode,
    "auto | sync | async: re-run inline, or on a worker while the node keeps publishing; auto = async in the LCM process");
}

/// Visits every option as (dotted key, field, unit/comment). The single list used for loading,
/// printing and the shipped YAML, so they cannot drift apart.
template <typename Opt, typename Visitor>
void forEachField(Opt& o, Visitor&& v) {
  forEachGeneralField(o, v);
  forEachInitField(o, v);
  forEachAltitudeField(o, v);
  forEachUwbField(o, v);
  forEachRestAndHealthField(o, v);
  forEachAdaptationField(o, v);
  forEachRefineField(o, v);
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
  EstimatorOptions o;
  forEachField(o, [&](const std::string& key, auto& field, const char*) { yaml.read(key, field); });
  yaml.rejectUnknown();
  try {
    o.validate();
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  return o;
}

void EstimatorOptions::validate() const {
  auto need = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("invalid option: " + what);
  };
  need(strategyListed(strategy), "strategy must be one of " + strategyNames(", "));
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
  need(imu.gap_sigma_acc_m_s2 >= 0.0 && imu.gap_sigma_gyro_rad_s >= 0.0, "imu.gap_sigma_* >= 0");
  need(init.static_max_sigma_yaw_deg > 0 && init.ambiguity_chi2 > 0 && init.motion_window_s >= init.motion_min_span_s &&
           init.motion_min_span_s > 0 && init.motion_min_ranges >= 8 && init.motion_max_sigma_yaw_deg > 0 &&
           init.motion_max_sigma_p_m > 0 && init.resume_max_age_s >= 0 && init.resume_max_acc_m_s2 >= 0 &&
           init.resume_max_rate_deg_s >= 0 && init.resume_max_outage_s >= 0,
       "init.motion_* (window >= min span > 0, min_ranges >= 8, sigmas > 0)");
  need(init.motion_relinearize_rad >= 0 && init.motion_relinearize_rad < M_PI, "init.motion_relinearize_rad in [0, pi)");
  need(health.window_s > 0 && health.min_ranges >= 1 && health.min_anchors >= 1 &&
           health.degraded_gated_fraction > 0 && health.degraded_gated_fraction <= health.lost_gated_fraction &&
           health.lost_gated_fraction <= 1 && health.degraded_mean_nis > 0 && health.degraded_no_aiding_s > 0 &&
           health.lost_no_aiding_s >= health.degraded_no_aiding_s && health.lost_sigma_p_m > 0 && health.hold_s >= 0,
       "health.* (0 < degraded <= lost fractions <= 1, positive times)");
  need(recovery.retry_s > 0 && recovery.degraded_disagreement_chi2 >= 0,
       "recovery.retry_s > 0, recovery.degraded_disagreement_chi2 >= 0");
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
  need(process_noise.batch >= 5 && process_noise.upper_ratio > 1.0 && process_noise.lower_ratio > 0.0 &&
           process_noise.lower_ratio < 1.0 && process_noise.max_grow > 1.0 && process_noise.max_shrink > 1.0 &&
           process_noise.max_scale >= 1.0 && process_noise.max_prior_ratio > 0.0 &&
           process_noise.min_accepted_fraction > 0.0 && process_noise.min_accepted_fraction <= 1.0 &&
           process_noise.confirm_batches >= 1 && process_noise.grow_at_once_ratio >= process_noise.upper_ratio,
       "process_noise: batch >= 5, lower_ratio in (0, 1), upper_ratio > 1, max_grow > 1, max_shrink > 1, max_scale >= 1, max_prior_ratio > 0, min_accepted_fraction in (0, 1], confirm_batches >= 1, grow_at_once_ratio >= upper_ratio");
  need(time.max_offset_s >= window_s && time.max_offset_s <= kMaxTimeSeconds && time.rebase_after >= 1,
       "time.max_offset_s >= window_s, time.rebase_after >= 1");
  need(refine.max_history_s >= window_s && refine.rerun_prior_sigma_m > 0 && refine.rerun_gamma_sigma_m > 0,
       "refine.max_history_s >= window_s, refine.rerun_prior_sigma_m > 0, refine.rerun_gamma_sigma_m > 0");
  need(refine.rerun_mode == "auto" || refine.rerun_mode == "sync" || refine.rerun_mode == "async",
       "refine.rerun_mode must be auto, sync or async");
  need(zupt.rate_hz > 0 && zupt.sigma_acc_m_s2 > 0 && zupt.sigma_gyro_rad_s > 0 && zupt.sigma_vel_m_s > 0 &&
           zupt.stillness_sigma_vel_m_s > 0 && zupt.stillness_sigma_gyro_rad_s > 0,
       "zupt rate and sigmas > 0");
}

void EstimatorOptions::applySetupNoise(const NoiseFigures& n) {
  if (n.imu_acc_noise_density) imu.acc_noise_density = *n.imu_acc_noise_density;
  if (n.imu_gyro_noise_density) imu.gyro_noise_density = *n.imu_gyro_noise_density;
  if (n.imu_acc_bias_rw) imu.acc_bias_rw = *n.imu_acc_bias_rw;
  if (n.imu_gyro_bias_rw) imu.gyro_bias_rw = *n.imu_gyro_bias_rw;
  if (n.imu_acc_bias_sigma) init.sigma_bias_acc_m_s2 = *n.imu_acc_bias_sigma;
  if (n.imu_gyro_bias_sigma) init.sigma_bias_gyro_rad_s = *n.imu_gyro_bias_sigma;
  if (n.baro_pressure_sigma_pa) baro.pressure_sigma_pa = *n.baro_pressure_sigma_pa;
}

std::string EstimatorOptions::toString() const {
  std::ostringstream os;
  std::vector<std::string> open;  // currently open YAML sections
  forEachField(*this, [&](const std::string& key, const auto& field, const char* unit) {
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

}  // namespace meshnav::estimator
