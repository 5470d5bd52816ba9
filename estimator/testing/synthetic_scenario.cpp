#include "estimator/testing/synthetic_scenario.h"

#include <cmath>
#include <random>

#include "common/atmosphere.h"
#include "estimator/core/so3.h"

namespace meshnav::estimator::synthetic {

namespace {
constexpr double kH = 1e-4;  // step of the numerical derivatives [s]
const Eigen::Vector3d kBaroLever(0.0, 0.0, 0.05);
constexpr double kBaroRefPa = 101325.0;

double ramp(double tau) { return tau <= 0.0 ? 0.0 : tau * tau * tau / (1.0 + tau * tau * tau); }
}  // namespace

Eigen::Vector3d SyntheticTrajectory::position(double t) const {
  const double tau = t - landed_s_, w = ramp(tau);
  return Eigen::Vector3d(0.2, -0.5, 0.1) +
         w * Eigen::Vector3d(1.5 * std::sin(0.7 * tau), 1.2 * (1.0 - std::cos(0.5 * tau)),
                             1.5 + 0.5 * std::sin(0.3 * tau));
}

Eigen::Matrix3d SyntheticTrajectory::rotation(double t) const {
  const double tau = t - landed_s_, w = ramp(tau);
  const double yaw = yaw0_ + w * (0.6 * std::sin(0.4 * tau) + 0.2 * tau);
  const double roll = w * 0.1 * std::sin(1.1 * tau);
  const double pitch = w * 0.08 * std::cos(0.9 * tau);
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d SyntheticTrajectory::velocity(double t) const {
  return (position(t + kH) - position(t - kH)) / (2.0 * kH);
}

Eigen::Vector3d SyntheticTrajectory::accelerationG(double t) const {
  const double h = 1e-3;
  return (position(t + h) - 2.0 * position(t) + position(t - h)) / (h * h);
}

Eigen::Vector3d SyntheticTrajectory::angularVelocityI(double t) const {
  return so3::logMap(Eigen::Matrix3d(rotation(t - kH).transpose() * rotation(t + kH))) / (2.0 * kH);
}

ImuSample SyntheticTrajectory::imu(double t, double gravity) const {
  ImuSample s;
  s.t = Timestamp::fromSec(t);
  s.acc_m_s2 = rotation(t).transpose() * (accelerationG(t) - Eigen::Vector3d(0.0, 0.0, -gravity));
  s.gyro_rad_s = angularVelocityI(t);
  return s;
}

std::map<SensorId, Eigen::Vector3d> syntheticAnchors(int n_estimated) {
  std::map<SensorId, Eigen::Vector3d> a = {{101, {-1.308, -4.140, 0.66}}, {102, {1.742, -4.147, 1.881}},
                                           {103, {2.914, 2.081, 2.172}},  {104, {0.18, -4.13, 3.242}}};
  const std::vector<Eigen::Vector3d> extra = {{-1.772, 0.943, 3.256}, {-2.021, 1.814, 1.732}, {-1.98, 0.069, 1.76},
                                              {0.433, 4.105, 0.925},  {2.59, -0.2, 0.33}};
  for (int i = 0; i < n_estimated; ++i) {
    const Eigen::Vector3d base = extra[static_cast<size_t>(i) % extra.size()];
    a[106 + i] = base + Eigen::Vector3d(0.0, 0.0, 0.7 * static_cast<double>(i / static_cast<int>(extra.size())));
  }
  return a;
}

SystemSetup syntheticSetup(const SyntheticOptions& o) {
  SystemSetup s;
  s.imu_id = 1;
  s.baro_id = 2;
  s.rel_tag_positions = {{100, {-0.19, 0.105, -0.07}}, {105, {0.05, -0.105, -0.07}}};
  for (const auto& [id, p] : syntheticAnchors(o.n_estimated_anchors)) {
    s.abs_anchor_positions[id] = p;
    if (id >= 106) s.abs_anchor_sigmas_m[id] = o.estimated_anchor_sigma_m;
  }
  // A few a-priori calibrated pair biases.
  s.pair_biases.push_back({100, 101, 0.12, 1.01, o.sigma_range_m, 0.0, 0.0});
  s.pair_biases.push_back({105, 103, -0.08, 0.99, o.sigma_range_m, 0.0, 0.0});
  s.baro_p_IP = kBaroLever;
  if (o.with_initial_pose) {
    SyntheticTrajectory traj(o.landed_s, o.yaw0_deg * M_PI / 180.0);
    InitialPose ip;
    ip.p_IinG = traj.position(0.0);
    ip.yaw_deg = o.yaw0_deg;
    ip.sigma_p_m = 0.05;
    ip.sigma_yaw_deg = 2.0;
    s.initial_pose = ip;
  }
  s.noise.sigma_range_m = o.sigma_range_m;
  s.noise.sigma_gamma_m = 0.0;  // the ranges below have γ = 0 for every unlisted pair: calibrated
  s.noise.range_correlation_time_s = 0.0;  // and independent errors
  s.noise.imu_acc_noise_density = o.acc_noise_density;
  s.noise.imu_gyro_noise_density = o.gyro_noise_density;
  s.noise.baro_pressure_sigma_pa = o.baro_sigma_pa;
  return s;
}

Dataset makeSyntheticDataset(const SyntheticOptions& o) {
  Dataset ds;
  ds.setup = syntheticSetup(o);
  SyntheticTrajectory traj(o.landed_s, o.yaw0_deg * M_PI / 180.0);
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  auto noise = [&](double sigma) { return o.noise ? sigma * n01(rng) : 0.0; };

  const int n_imu = static_cast<int>(std::floor(o.duration_s * o.imu_rate_hz)) + 1;
  for (int k = 0; k < n_imu; ++k) {
    const double t = k / o.imu_rate_hz;
    ImuSample s = traj.imu(t);
    const double sa = o.acc_noise_density * std::sqrt(o.imu_rate_hz);
    const double sg = o.gyro_noise_density * std::sqrt(o.imu_rate_hz);
    s.acc_m_s2 += o.bias_acc_m_s2 + Eigen::Vector3d(noise(sa), noise(sa), noise(sa));
    s.gyro_rad_s += o.bias_gyro_rad_s + Eigen::Vector3d(noise(sg), noise(sg), noise(sg));
    ds.imu.push_back(s);
    PoseSample gt;
    gt.t = s.t;
    gt.p_IinG = traj.position(t);
    gt.q_ItoG = Eigen::Quaterniond(traj.rotation(t)).normalized();
    ds.ground_truth.push_back(gt);
  }
  for (double t = 0.0; t <= o.duration_s; t += 1.0 / o.baro_rate_hz) {
    const double h = (traj.position(t) + traj.rotation(t) * kBaroLever).z();
    ds.baro.push_back({Timestamp::fromSec(t), atmosphere::pressureFromHeight(h, kBaroRefPa) + noise(o.baro_sigma_pa)});
  }
  ds.flight_states.push_back({Timestamp::fromSec(0.0), true});
  ds.flight_states.push_back({Timestamp::fromSec(o.landed_s), false});

  // Ordered pairs, staggered over the period.
  const auto anchors = syntheticAnchors(o.n_estimated_anchors);
  std::vector<std::pair<SensorId, SensorId>> pairs;
  for (const auto& [tag, lever] : ds.setup.rel_tag_positions)
    for (const auto& [a, p] : anchors) {
      pairs.emplace_back(tag, a);
      pairs.emplace_back(a, tag);
    }
  if (o.anchor_to_anchor)
    for (const auto& [a, pa] : anchors)
      for (const auto& [b, pb] : anchors)
        if (a != b) pairs.emplace_back(a, b);
  const double period = 1.0 / o.pair_rate_hz;
  for (double t0 = 0.0; t0 < o.duration_s; t0 += period) {
    for (size_t i = 0; i < pairs.size(); ++i) {
      const double t = t0 + period * static_cast<double>(i) / static_cast<double>(pairs.size());
      if (t > o.duration_s) break;
      const auto [a, b] = pairs[i];
      auto where = [&](SensorId id) -> Eigen::Vector3d {
        auto it = ds.setup.rel_tag_positions.find(id);
        if (it != ds.setup.rel_tag_positions.end()) return traj.position(t) + traj.rotation(t) * it->second;
        return anchors.at(id);
      };
      const double d = (where(a) - where(b)).norm();
      double gamma = 0.0, beta = 1.0;
      if (auto pb = ds.setup.findPairBias(a, b)) {
        gamma = pb->gamma_m;
        beta = pb->beta;
      }
      RangeSample r;
      r.t = Timestamp::fromSec(t);
      r.id_initiator = a;
      r.id_responder = b;
      r.type_initiator = ds.setup.isTag(a) ? UwbType::Tag : UwbType::Anchor;
      r.type_responder = ds.setup.isTag(b) ? UwbType::Tag : UwbType::Anchor;
      r.range_m = beta * d + gamma + noise(o.sigma_range_m);
      r.range_corr_m = r.range_m;
      r.R_m2 = o.sigma_range_m * o.sigma_range_m;
      ds.ranges.push_back(r);
    }
  }
  return ds;
}

}  // namespace meshnav::estimator::synthetic
