/// @file resume.cpp
/// @brief The checkpoint of a running estimator and the resume of a restarted one (resume.h).

#include "estimator/restart/resume.h"

#include <spdlog/spdlog.h>

#include <cmath>

namespace meshnav::estimator {

EstimatorCheckpoint makeCheckpoint(const FusionStrategy& f, const UwbNetwork& network, bool landed,
                                   const std::optional<double>& baro_reference_pa, const EstimatorOptions& options,
                                   bool with_anchors) {
  const NominalState& x = f.state();
  EstimatorCheckpoint c;
  c.t = x.t;
  c.imu_id = x.imu_id;
  c.imu = x.imu;
  c.cov_imu = f.covariance(x.imu_id, x.imu_id);
  c.landed = landed;
  c.baro_reference_pa = baro_reference_pa;
  // Every instance whose kind a restart keeps (K::restart), in registry order.
  forEachKind([&]<class K>() {
    if constexpr (!K::kBody) {
      if (K::restart(options) != Restart::kKept) return;
      for (const auto& [id, value] : x.values<K>())
        c.instances.push_back({K::kName, id, K::peersOf(value), K::toVector(value), f.covariance(id, id)});
    }
  });
  if (!with_anchors) return c;
  // Every device an anchor may have a pair bias with.
  std::vector<SensorId> devices;
  for (const auto& [id, p] : network.tags()) devices.push_back(id);
  for (const auto& [id, p] : network.exactAnchors()) devices.push_back(id);
  for (const auto& [id, anchor] : x.values<AnchorKind>()) devices.push_back(id);
  for (const auto& [id, anchor] : x.values<AnchorKind>()) {
    AnchorInit a;
    a.t = x.t;
    a.id = id;
    a.p_AinG = anchor.p_AinG;
    const Eigen::MatrixXd C = f.covariance(id, id);
    a.cov_p_m2 = C.topLeftCorner<3, 3>();
    // γ states: their current values and the joint covariance with the position (row of each
    // bias in C, or −1 for a dictionary value).
    const BiasState& gs = anchor.biases;
    std::vector<int> row;
    for (SensorId d : devices) {
      if (d == id || !network.hasPairBias(d, id)) continue;
      PairBias pb = network.pairBias(d, id);
      pb.a = d;
      pb.b = id;
      const int i = gs.index(d);
      if (i >= 0) {
        pb.gamma_m = gs.gamma_m(i);
        pb.sigma_gamma_m = std::sqrt(C(3 + i, 3 + i));
      }
      row.push_back(i < 0 ? -1 : 3 + i);
      a.biases.push_back(pb);
    }
    if (!gs.peers.empty()) {
      const auto n = static_cast<Eigen::Index>(a.biases.size());
      a.cov_gamma_p_m2 = Eigen::MatrixXd::Zero(n, 3);
      a.cov_gamma_m2 = Eigen::MatrixXd::Zero(n, n);
      for (Eigen::Index k = 0; k < n; ++k) {
        const int rk = row[static_cast<size_t>(k)];
        if (rk < 0) {
          a.cov_gamma_m2(k, k) = std::pow(a.biases[static_cast<size_t>(k)].sigma_gamma_m, 2);
          continue;
        }
        a.cov_gamma_p_m2.row(k) = C.block(rk, 0, 1, 3);
        for (Eigen::Index l = 0; l < n; ++l)
          if (row[static_cast<size_t>(l)] >= 0) a.cov_gamma_m2(k, l) = C(rk, row[static_cast<size_t>(l)]);
      }
    }
    c.anchors.push_back(std::move(a));
  }
  return c;
}

std::optional<InitialBelief> Resume::at(const ImuSample& s, std::vector<AnchorInit>& anchors) {
  EstimatorCheckpoint c = std::move(*offered_);
  offered_.reset();
  const double dt = (s.t - c.t).sec();
  if (dt < 0.0 || dt > options_.init.resume_max_age_s) {
    diag_.report("resume_refused", "estimator: checkpoint of t=" + formatSeconds(c.t) + " not used at t=" +
                                       formatSeconds(s.t) + " (" + std::to_string(dt) + " s old, limit " +
                                       std::to_string(options_.init.resume_max_age_s) + " s); initializing anew");
    return std::nullopt;
  }
  // Anchors (through the ANCHOR_INIT path once the filter exists), the baro reference and the
  // kept instances (Restart::kKept) come back whatever the outage; the pose only across a short one.
  const size_t n_anchors = c.anchors.size(), n_kept = c.instances.size();
  for (auto& a : c.anchors) anchors.push_back(std::move(a));
  c.anchors.clear();
  kept_ = c;
  diag_.count("resumed");
  if (dt > options_.init.resume_max_outage_s) {
    spdlog::warn("estimator: restart {:.3f} s after the checkpoint of t={}: {} anchors, {} other instances and the "
                 "baro reference kept, the pose is initialized anew (outage longer than {} s)",
                 dt, formatSeconds(c.t), n_anchors, n_kept, options_.init.resume_max_outage_s);
    return std::nullopt;
  }
  // Across the outage: position moved with the velocity (Φ_pv = I·dt); what the body did meanwhile
  // is unknown, bounded by a largest acceleration a and rotation rate ω: velocity σ += a·dt,
  // position σ += a·dt²/2, attitude σ += ω·dt about each axis.
  ImuMatrix Phi = ImuMatrix::Identity();
  Phi.block<3, 3>(ImuErr::kP, ImuErr::kV) = Eigen::Matrix3d::Identity() * dt;
  InitialBelief b;
  b.t = s.t;
  b.imu = c.imu;
  b.imu.p_IinG += c.imu.v_IinG * dt;
  b.cov = Phi * c.cov_imu * Phi.transpose();
  const double a = options_.init.resume_max_acc_m_s2, w = options_.init.resume_max_rate_deg_s * M_PI / 180.0;
  const Eigen::Matrix3d I3 = Eigen::Matrix3d::Identity();
  b.cov.block<3, 3>(ImuErr::kV, ImuErr::kV) += I3 * std::pow(a * dt, 2);
  b.cov.block<3, 3>(ImuErr::kP, ImuErr::kP) += I3 * std::pow(0.5 * a * dt * dt, 2);
  b.cov.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) += I3 * std::pow(w * dt, 2);
  b.from_checkpoint = true;
  b.baro_reference_pa = c.baro_reference_pa;  // the baro bias comes with the kept instances
  b.last_imu = s;
  b.landed = c.landed;
  spdlog::warn("estimator: resuming from the checkpoint of t={} ({:.3f} s before the first IMU sample), {} anchors, "
               "{} other instances",
               formatSeconds(c.t), dt, n_anchors, n_kept);
  return b;
}

void Resume::restoreKept(FusionStrategy& f, Timestamp t, const std::optional<double>& baro_reference_pa) {
  if (!kept_) return;
  const EstimatorCheckpoint& c = *kept_;
  const double dt = std::max(0.0, (t - c.t).sec());
  int n = 0;
  forEachKind([&]<class K>() {
    if constexpr (!K::kBody) {
      if (K::restart(options_) != Restart::kKept) return;
      for (const InstanceRecord& r : c.instances) {
        if (r.kind != K::kName) continue;
        // A baro bias is relative to its reference pressure: not used against another one.
        if (r.id == setup_.baro_id && baro_reference_pa != c.baro_reference_pa) continue;
        Eigen::MatrixXd cov = r.cov;  // grown by the kind's random walk over the outage
        cov.diagonal().array() += std::pow(K::randomWalk(options_), 2) * dt;
        f.addInstance<K>(r.id, K::fromVector(r.value, r.peers), cov);
        ++n;
      }
    }
  });
  if (n > 0) diag_.count("resumed_instances", n);
  kept_.reset();
}

}  // namespace meshnav::estimator
