#include "eval/trajectory_alignment.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>

namespace meshnav::eval {

std::optional<AlignmentMode> parseAlignmentMode(const std::string& text) {
  if (text == "none") return AlignmentMode::None;
  if (text == "se3") return AlignmentMode::Se3;
  if (text == "yaw") return AlignmentMode::Yaw;
  return std::nullopt;
}

std::string toString(AlignmentMode mode) {
  switch (mode) {
    case AlignmentMode::Se3: return "se3";
    case AlignmentMode::Yaw: return "yaw";
    case AlignmentMode::None: break;
  }
  return "none";
}

PoseEstimate RigidTransform::apply(const PoseEstimate& est) const {
  PoseEstimate out = est;
  out.p_IinG = apply(est.p_IinG);
  out.v_IinG = R_EtoT * est.v_IinG;
  out.q_ItoG = Eigen::Quaterniond(R_EtoT) * est.q_ItoG;
  out.q_ItoG.normalize();
  out.cov_p_m2 = R_EtoT * est.cov_p_m2 * R_EtoT.transpose();
  out.cov_v = R_EtoT * est.cov_v * R_EtoT.transpose();
  return out;
}

namespace {

/// Rotation of Umeyama's method from the cross-covariance Σ_gp; nullopt if it has rank < 2.
std::optional<Eigen::Matrix3d> umeyamaRotation(const Eigen::Matrix3d& sigma_gp) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(sigma_gp, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d s = svd.singularValues();
  if (!(s(0) > 0.0) || s(1) <= 1e-12 * s(0)) return std::nullopt;
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;
  return svd.matrixU() * S * svd.matrixV().transpose();
}

/// Yaw rotation R_z(ψ) minimising Σ ‖g' − R_z p'‖² over centred points; nullopt if undetermined.
std::optional<Eigen::Matrix3d> yawRotation(const std::vector<Eigen::Vector3d>& p, const std::vector<Eigen::Vector3d>& g,
                                           const Eigen::Vector3d& mu_p, const Eigen::Vector3d& mu_g) {
  double sin_sum = 0.0, cos_sum = 0.0, scale = 0.0;
  for (size_t k = 0; k < p.size(); ++k) {
    const Eigen::Vector3d a = p[k] - mu_p, b = g[k] - mu_g;
    sin_sum += a.x() * b.y() - a.y() * b.x();
    cos_sum += a.x() * b.x() + a.y() * b.y();
    scale += a.head<2>().norm() * b.head<2>().norm();
  }
  if (!(scale > 0.0) || std::hypot(sin_sum, cos_sum) <= 1e-12 * scale) return std::nullopt;
  return Eigen::AngleAxisd(std::atan2(sin_sum, cos_sum), Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace

std::optional<RigidTransform> alignPositions(const std::vector<Eigen::Vector3d>& p_est_E,
                                             const std::vector<Eigen::Vector3d>& p_true_T, AlignmentMode mode) {
  if (mode == AlignmentMode::None) return RigidTransform{};
  const size_t n = p_est_E.size();
  const size_t needed = mode == AlignmentMode::Se3 ? 3 : 2;
  if (n != p_true_T.size() || n < needed) return std::nullopt;
  Eigen::Vector3d mu_p = Eigen::Vector3d::Zero(), mu_g = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < n; ++k) {
    mu_p += p_est_E[k];
    mu_g += p_true_T[k];
  }
  mu_p /= static_cast<double>(n);
  mu_g /= static_cast<double>(n);
  std::optional<Eigen::Matrix3d> R;
  if (mode == AlignmentMode::Se3) {
    Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero();
    for (size_t k = 0; k < n; ++k) sigma += (p_true_T[k] - mu_g) * (p_est_E[k] - mu_p).transpose();
    R = umeyamaRotation(sigma / static_cast<double>(n));
  } else {
    R = yawRotation(p_est_E, p_true_T, mu_p, mu_g);
  }
  if (!R) return std::nullopt;
  RigidTransform T;
  T.R_EtoT = *R;
  T.t_EinT_m = mu_g - *R * mu_p;
  return T;
}

}  // namespace meshnav::eval
