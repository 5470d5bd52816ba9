#include "calibrator/observation_builder.h"

#include <algorithm>
#include <cmath>

#include "common/pose_interpolation.h"
#include "common/skew.h"

namespace meshnav::calib {

ObservationBuilder::ObservationBuilder(SystemSetup setup, const CalibratorOptions& options)
    : setup_(std::move(setup)), options_(options) {}

void ObservationBuilder::setPoses(std::vector<PoseEstimate> poses) {
  poses_ = std::move(poses);
  std::stable_sort(poses_.begin(), poses_.end(), [](const auto& a, const auto& b) { return a.t < b.t; });
}

void ObservationBuilder::setPoses(const std::vector<PoseSample>& poses) {
  std::vector<PoseEstimate> v;
  v.reserve(poses.size());
  for (const auto& p : poses) {
    PoseEstimate e;
    e.t = p.t;
    e.p_IinG = p.p_IinG;
    e.q_ItoG = p.q_ItoG;
    v.push_back(e);
  }
  setPoses(std::move(v));
}

std::optional<std::pair<Eigen::Vector3d, Eigen::Matrix3d>> ObservationBuilder::tagPosition(SensorId tag,
                                                                                          Timestamp t) const {
  const auto lever = setup_.rel_tag_positions.find(tag);
  if (lever == setup_.rel_tag_positions.end()) return std::nullopt;
  const auto pose = interpolateEstimate(poses_, t, Duration::fromSec(options_.max_pose_gap_s));
  if (!pose) return std::nullopt;
  return tagPositionAtPose(*pose, lever->second, options_.min_tag_position_sigma_m);
}

std::pair<Eigen::Vector3d, Eigen::Matrix3d> tagPositionAtPose(const PoseEstimate& pose, const Eigen::Vector3d& p_TinI,
                                                              double min_sigma_m) {
  const Eigen::Matrix3d R = pose.q_ItoG.toRotationMatrix();
  const Eigen::Matrix3d J = R * skew(p_TinI);  // ∂p_T/∂δθ = −R[l]ₓ; the sign cancels in J Σ Jᵀ
  Eigen::Matrix3d cov = pose.cov_p_m2 + J * pose.cov_theta_rad2 * J.transpose();
  cov += min_sigma_m * min_sigma_m * Eigen::Matrix3d::Identity();
  return {pose.p_IinG + R * p_TinI, cov};
}

CalibObservation rangeObservation(const RangeSample& r, SensorId x, const CalibratorOptions& options) {
  CalibObservation o;
  o.t = r.t;
  o.ref_id = r.id_initiator == x ? r.id_responder : r.id_initiator;
  o.z_m = r.range_m;
  o.sigma_d_m = (options.use_range_variance && r.R_m2 > 0) ? std::sqrt(r.R_m2) : options.sigma_range_m;
  return o;
}

std::vector<CalibObservation> ObservationBuilder::collect(SensorId x, const std::vector<RangeSample>& ranges,
                                                          Diagnostics& diag, std::optional<Timestamp> t_start,
                                                          std::optional<Timestamp> t_end) const {
  std::vector<CalibObservation> out;
  for (const auto& r : ranges) {
    if (r.id_initiator != x && r.id_responder != x) continue;
    if (t_start && r.t < *t_start) continue;
    if (t_end && r.t > *t_end) continue;
    const SensorId ref = r.id_initiator == x ? r.id_responder : r.id_initiator;
    if (ref == x || !std::isfinite(r.range_m)) {
      diag.report("calibrator:bad_range", "range at t=" + formatSeconds(r.t) + " between " + std::to_string(r.id_initiator) +
                                              " and " + std::to_string(r.id_responder) + " is unusable");
      continue;
    }
    CalibObservation o = rangeObservation(r, x, options_);
    if (setup_.isTag(ref)) {
      // The pose when the range was measured: its stamp less the UWB stamps' delay of setup.yaml
      // (uwb_clock.offset_s; the estimator's estimate of it is not the calibrator's to know).
      const auto tp = tagPosition(ref, r.t - Duration::fromSec(setup_.uwb_clock.offset_s));
      if (!tp) {
        diag.count("calibrator:range_without_pose");
        continue;
      }
      o.p_RinG = tp->first;
      o.cov_p_RinG_m2 = tp->second;
    } else if (setup_.isKnownAnchor(ref)) {
      o.p_RinG = setup_.abs_anchor_positions.at(ref);
      const auto sig = setup_.abs_anchor_sigmas_m.find(ref);
      const double s = sig == setup_.abs_anchor_sigmas_m.end() ? 0.0 : sig->second;
      o.cov_p_RinG_m2 = s * s * Eigen::Matrix3d::Identity();
    } else {
      // Another anchor of unknown position (or an id the setup does not know): no reference.
      diag.count("calibrator:range_to_unknown_device");
      continue;
    }
    out.push_back(o);
  }
  return out;
}

std::map<SensorId, ReferencePrior> ObservationBuilder::priors(SensorId x) const {
  std::map<SensorId, ReferencePrior> out;
  for (const auto& b : setup_.pair_biases) {
    if (b.a != x && b.b != x) continue;
    ReferencePrior p;
    p.ref_id = b.a == x ? b.b : b.a;
    p.gamma_m = b.gamma_m;
    p.sigma_gamma_m = b.sigma_gamma_m > 0 ? b.sigma_gamma_m : options_.gamma_prior_sigma_m;
    p.beta = b.beta;
    p.sigma_beta = b.sigma_beta > 0 ? b.sigma_beta : options_.beta_prior_sigma;
    out[p.ref_id] = p;
  }
  return out;
}

}  // namespace meshnav::calib
