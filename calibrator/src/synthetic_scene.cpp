#include "calibrator/synthetic_scene.h"

#include <cmath>
#include <random>

namespace meshnav::calib {

namespace {
/// IMU position and yaw along the configured path at time t [s].
void bodyOnPath(const SyntheticSceneConfig& cfg, double t, Eigen::Vector3d& p, double& yaw) {
  const double turns_per_s = 3.0 / 120.0;
  const double a = 2.0 * M_PI * turns_per_s * t;
  switch (cfg.path) {
    case SyntheticPath::Spiral:
      p = Eigen::Vector3d(0.3 + 2.0 * std::cos(a), 2.5 * std::sin(a), 1.0 + 7.0 * t / 120.0);
      yaw = a + M_PI / 2;
      break;
    case SyntheticPath::Planar:
      p = Eigen::Vector3d(0.3 + 2.0 * std::cos(a), 2.5 * std::sin(a), 2.0);
      yaw = a + M_PI / 2;
      break;
    case SyntheticPath::Walk:
      p = Eigen::Vector3d(0.3 + 2.0 * std::cos(a), 2.5 * std::sin(a), 1.2 + 0.12 * std::sin(2.0 * M_PI * 1.8 * t));
      yaw = a + M_PI / 2;
      break;
    case SyntheticPath::Line:
      p = Eigen::Vector3d(-2.0 + 4.0 * t / std::max(1.0, cfg.duration_s), 0.5, 2.0);
      yaw = 0.0;
      break;
    case SyntheticPath::Hover:
      p = Eigen::Vector3d(0.3, 0.0, 2.0);
      yaw = 0.0;
      break;
  }
}
}  // namespace

SyntheticScene makeSyntheticScene(const SyntheticSceneConfig& cfg) {
  SyntheticScene sc;
  sc.p_AinG = cfg.p_AinG;
  std::mt19937_64 rng(cfg.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> u01(0.0, 1.0);

  const std::map<SensorId, Eigen::Vector3d> tags = {{100, {-0.19, 0.105, -0.07}}, {105, {0.05, -0.105, -0.07}}};
  const std::map<SensorId, Eigen::Vector3d> anchors = {{101, {-1.308, -4.140, 0.66}},
                                                       {102, {1.742, -4.147, 1.881}},
                                                       {103, {2.914, 2.081, 2.172}},
                                                       {104, {0.18, -4.13, 3.242}}};
  std::vector<SensorId> refs;
  for (const auto& [id, l] : tags) refs.push_back(id);
  if (cfg.known_anchors)
    for (const auto& [id, p] : anchors) refs.push_back(id);
  for (SensorId r : refs) {
    sc.gamma_m[r] = cfg.gamma_max_m * (2.0 * u01(rng) - 1.0);
    sc.beta[r] = tags.count(r) ? 1.0 + cfg.beta_sigma * n01(rng) : 1.0;
  }

  const int n = cfg.n_ranges;
  for (int k = 0; k < n; ++k) {
    const double t = cfg.duration_s * (k + 0.5) / n;
    const SensorId r = refs[static_cast<size_t>(k) % refs.size()];
    Eigen::Vector3d p_ref;
    bool is_tag = tags.count(r) > 0;
    if (is_tag) {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      double yaw = 0.0;
      bodyOnPath(cfg, t, p, yaw);
      p_ref = p + Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * tags.at(r);
    } else {
      p_ref = anchors.at(r);
    }
    const double d = (cfg.p_AinG - p_ref).norm();
    CalibObservation o;
    o.t = Timestamp::fromSec(t);
    o.ref_id = r;
    o.z_m = sc.beta[r] * d + sc.gamma_m[r] + cfg.sigma_d_m * n01(rng);
    const bool outlier = u01(rng) < cfg.outlier_fraction;
    if (outlier) o.z_m += 0.5 + 2.5 * u01(rng);
    o.p_RinG = p_ref;
    if (is_tag && cfg.sigma_ref_m > 0) {
      o.p_RinG += cfg.sigma_ref_m * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
      o.cov_p_RinG_m2 = cfg.sigma_ref_m * cfg.sigma_ref_m * Eigen::Matrix3d::Identity();
    }
    o.sigma_d_m = cfg.model_sigma_d_m > 0 ? cfg.model_sigma_d_m : cfg.sigma_d_m;
    sc.observations.push_back(o);
    sc.is_outlier.push_back(outlier);
  }
  return sc;
}

}  // namespace meshnav::calib
