/// @file estimator_node_updates.cpp
/// @brief EstimatorNode, the measurement updates: baro (height from pressure against the reference
/// taken at the first sample), height above the floor, UWB range and anchor initialization, each
/// counted per sensor. The first part, estimator_node.cpp, holds input handling, processing and
/// outputs.

#include <spdlog/spdlog.h>

#include <cmath>

#include "common/atmosphere.h"
#include "estimator/filter/joint_set_bound.h"
#include "estimator/node/estimator_node.h"
#include "estimator/node/node_internals.h"
#include "estimator/uwb/range_model.h"

namespace meshnav::estimator {

using node_internal::where;

void EstimatorNode::processBaro(const BaroSample& s, bool first) {
  if (!baro_.enabled()) return;
  if (!baro_.reference()) {
    event(first, "baro_no_reference");
    return;
  }
  propagateTo(s.t);
  ScopedStepTimer timer(timings_, "baro_update");
  const UpdateResult r = baro_.update(*cur_.filter, s);
  if (first) countScalarUpdate(s.t, setup_.baro_id, "baro", r);
}

void EstimatorNode::countScalarUpdate(Timestamp t, SensorId id, const std::string& type, const UpdateResult& r) {
  InstanceStatus& st = instance_stats_[id];
  health_.onUpdate(t, type, 0, r.accepted, r.nis);
  if (r.accepted) {
    ++st.n_updates;
  } else {
    ++st.n_rejected;
    diag_.count("gated_" + type);
  }
}

void EstimatorNode::processHeight(const HeightSample& s, bool first) {
  if (!height_.enabled()) return;
  if (const std::string why = height_.refusal(*cur_.filter, s); !why.empty()) {
    if (why == "height_id_is_an_anchor")
      event(first, why,
            where("HEIGHT", s.t) + ": height_id " + std::to_string(setup_.height_id) +
                " is an estimated anchor's id; heights not used (set height_id in setup.yaml)");
    else
      event(first, why);
    return;
  }
  height_.ensureBiasState(*cur_.filter, s.t, first);
  propagateTo(s.t);
  ScopedStepTimer timer(timings_, "height_update");
  const UpdateResult r = height_.update(*cur_.filter, s);
  if (first) countScalarUpdate(s.t, setup_.height_id, height_.typeName(), r);
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
  if (skip_estimated_anchor_pairs_ && cur_.filter->state().values<AnchorKind>().count(z.a) &&
      cur_.filter->state().values<AnchorKind>().count(z.b)) {
    event(first, "range_dah_anchor_pair_skipped");  // a policy, not bad input (see UwbOptions)
    return;
  }
  if (!options_.uwb.fuse_calibrated_anchor_pairs && cur_.network->isCalibrated(z.a) &&
      cur_.network->isCalibrated(z.b)) {
    event(first, "range_calibrated_anchor_pair_skipped");  // a policy (see UwbOptions)
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
  lin.huber_k = options_.uwb.huber_k;
  lin.huber_max_prior_ratio = options_.uwb.huber_max_prior_ratio;
  const bool tag_range = cur_.network->isTag(z.a) || cur_.network->isTag(z.b);
  bool count = first;
  if (tag_range &&
      !reentry_.admit(s, cur_.network->isTag(z.a) ? z.b : z.a, lin, *cur_.filter, init_time_, first, &count))
    return;
  const UpdateResult r = cur_.filter->update(lin, range_gate_);
  // H P Hᵀ / R from NIS = ν²/S, S = H P Hᵀ + R (scalar range).
  const double nu2 = lin.residual(0) * lin.residual(0), R = lin.R(0, 0);
  const double prior_ratio = r.nis > 0.0 && R > 0.0 ? std::max(0.0, nu2 / r.nis - R) / R : 0.0;
  const long decisions = cur_.noise_adapter.decisions();
  if (tag_range && cur_.noise_adapter.onRangeNis(r.nis, prior_ratio, r.accepted) && first) {
    diag_.count("process_noise_scale_change");
    spdlog::info("estimator: IMU noise scale {:.3g} at t={} (median range NIS {:.2f} of its expected value)",
                 cur_.noise_adapter.scale(), formatSeconds(s.t), cur_.noise_adapter.lastRatio());
  }
  // Every batch's median NIS, whether λ changed or not (it holds at its bound, or while H P Hᵀ ≫ R).
  if (first && cur_.noise_adapter.decisions() != decisions) gravity_.noteRangeNisRatio(cur_.noise_adapter.lastRatio());
  if (!count) return;
  if (!r.accepted) diag_.count("gated_range");
  if (tag_range && r.accepted) reentry_.noteAccepted(s.t);
  // Tag ranges tell whether the pose is right; ranges between anchors do not.
  if (tag_range)
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
  // An id holds one instance: a tag's, the IMU's, the baro's, or a height bias already added.
  const bool height = cur_.filter->state().values<HeightBiasKind>().count(a.id) > 0;
  if (net->isTag(a.id) || setup_.isSensorInstanceId(a.id) || height) {
    event(first, "bad_command",
          where("ANCHOR_INIT", a.t) + ": id " + std::to_string(a.id) +
              (net->isTag(a.id) ? " is a tag"
                                : " is the IMU's, the baro's or the height sensor's (imu_id, baro_id, height_id in "
                                  "setup.yaml)"));
    return;
  }
  net->removeDevice(a.id);  // an exactly known anchor becomes an estimated one
  net->setCalibrated(a.id, true);
  for (PairBias b : a.biases) {
    if (b.a != a.id && b.b != a.id) b.b = a.id;
    net->setPairBias(b);
  }
  cur_.network = std::move(net);
  // The anchor's γ with an uncertainty become states after its position (issue 10), with the
  // calibration's joint covariance: a γ error and the position error along that reference's
  // direction are strongly correlated, and fixing γ would let repeated ranges average away an
  // error that is constant.
  BiasState biases;
  std::vector<Eigen::Index> rows = {0, 1, 2};  // rows of the joint [p, γ_1..γ_n] kept
  std::vector<double> gamma;
  if (options_.uwb.estimate_anchor_biases) {
    for (size_t i = 0; i < a.biases.size(); ++i) {
      const PairBias& b = a.biases[i];
      const SensorId peer = b.a == a.id ? b.b : b.a;
      if (peer == a.id || b.sigma_gamma_m <= 0.0 || biases.index(peer) >= 0) continue;
      biases.peers.push_back(peer);
      gamma.push_back(b.gamma_m);
      rows.push_back(3 + static_cast<Eigen::Index>(i));
    }
  }
  biases.gamma_m = Eigen::Map<const Eigen::VectorXd>(gamma.data(), static_cast<Eigen::Index>(gamma.size()));
  AnchorInit marginal = a;
  if (!options_.uwb.anchor_bias_joint_covariance) marginal.cov_gamma_p_m2.resize(0, 0), marginal.cov_gamma_m2.resize(0, 0);
  const Eigen::MatrixXd J = marginal.jointCovariance();
  Eigen::MatrixXd cov(rows.size(), rows.size());
  for (size_t r = 0; r < rows.size(); ++r)
    for (size_t c = 0; c < rows.size(); ++c) cov(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = J(rows[r], rows[c]);
  cur_.filter->addInstance<AnchorKind>(a.id, AnchorState{a.p_AinG, biases}, cov);
  joinAnchorSet(a.id);
  if (first) {
    diag_.count("anchor_init");
    spdlog::info("estimator: anchor {} added at t={} p_AinG=[{:.3f}, {:.3f}, {:.3f}] with {} pair biases, {} as states{}",
                 a.id, formatSeconds(a.t), a.p_AinG.x(), a.p_AinG.y(), a.p_AinG.z(), a.biases.size(),
                 biases.peers.size(),
                 biases.peers.empty() ? ""
                 : a.hasJointCovariance() && options_.uwb.anchor_bias_joint_covariance ? " (joint covariance)"
                                                                                        : " (independent of the position)");
  }
}

void EstimatorNode::joinAnchorSet(SensorId id) {
  const std::string& mode = options_.uwb.dah_joint_anchors;
  if (options_.strategy != "dah" || mode == "none") return;
  const Timestamp t = cur_.filter->state().t;
  if (!anchor_batch_t_ || *anchor_batch_t_ != t) anchor_batch_.clear();
  anchor_batch_t_ = t;
  anchor_batch_.push_back(id);
  std::vector<SensorId> set = anchor_batch_;
  if (mode == "all")
    for (const auto& [other, value] : cur_.filter->state().values<AnchorKind>())
      if (cur_.network->isCalibrated(other)) set.push_back(other);
  if (options_.uwb.dah_joint_tag_biases)  // merges every batch into one set with the tags' γ
    for (const auto& [tag, value] : cur_.filter->state().values<TagBiasKind>()) set.push_back(tag);
  if (options_.uwb.dah_joint_imu) {
    // With the IMU the biases of its vertical aids (baro, height sensor): a range correlates them
    // with every member through the pose, and left outside they would keep each member's DAH
    // correction (and its cost) on every update of the set.
    set.push_back(cur_.filter->state().imu_id);
    for (const auto& [baro, value] : cur_.filter->state().values<BaroBiasKind>()) set.push_back(baro);
    for (const auto& [height, value] : cur_.filter->state().values<HeightBiasKind>()) set.push_back(height);
  }
  cur_.filter->joinJointSet(set);
  boundJointSetAnchors(*cur_.filter, id, options_.uwb.dah_joint_max_anchors);
}

/// Zero-velocity update at the IMU reading `s` while landed (rate `zupt.rate_hz`): v = 0, the
/// specific force of gravity alone, and ω = 0 on the mean gyro reading since the last ZUPT.
void EstimatorNode::processZupt(const ImuSample& s, bool first) {
  FusionStrategy& f = *cur_.filter;
  ScopedStepTimer timer(timings_, "zupt");
  ZuptMeasurement z;
  z.t = s.t;
  z.acc_m_s2 = s.acc_m_s2;
  // Only a flight state says v = 0 and ω = 0 exactly; IMU stillness allows a slow drift and turn.
  z.sigma_acc_m_s2 = options_.zupt.sigma_acc_m_s2;
  // ω row: the mean reading since the last ZUPT, σ² = (rest rotation allowed)² + σ_ω² λ / T
  // (RestRateMean; λ the IMU noise scale); the latest reading with the loosest σ before any interval.
  const double rest_sigma = init_.haveFlightState() ? options_.zupt.sigma_gyro_rad_s : options_.zupt.stillness_sigma_gyro_rad_s;
  if (cur_.rest_rate.span() > 0.0) {
    const double mean_sigma = cur_.rest_rate.sigma(options_.imu.gyro_noise_density * std::sqrt(cur_.noise_adapter.scale()));
    z.gyro_rad_s = cur_.rest_rate.mean();
    z.sigma_gyro_rad_s = std::hypot(rest_sigma, mean_sigma);
  } else {
    z.gyro_rad_s = s.gyro_rad_s;
    z.sigma_gyro_rad_s = std::max(rest_sigma, options_.zupt.stillness_sigma_gyro_rad_s);
  }
  z.sigma_vel_m_s = init_.haveFlightState() ? options_.zupt.sigma_vel_m_s : options_.zupt.stillness_sigma_vel_m_s;
  const Linearization lin = zupt_model_.linearize(z, f.state());
  const double gate = init_.haveFlightState() ? 0.0 : chi2Quantile(static_cast<int>(lin.residual.size()),
                                                              options_.zupt.stillness_gate_probability);
  if (!f.update(lin, gate).accepted) event(first, "gated_zupt");
  cur_.last_zupt = s.t;
  cur_.rest_rate.reset();
  if (first) ++instance_stats_[setup_.imu_id].n_updates;
}

}  // namespace meshnav::estimator
