#pragma once
/// @file so3.h
/// @brief Small SO(3) helpers for the error-state filter (header-only, fixed-size Eigen).
///
/// Conventions: Exp(φ) = rotation by angle |φ| about φ/|φ|; the right Jacobian
/// J_r(φ) = I − (1 − cos θ)/θ² [φ]× + (θ − sin θ)/θ³ [φ]×², θ = |φ|, satisfies
/// Exp(φ + δφ) ≈ Exp(φ) Exp(J_r(φ) δφ).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "common/skew.h"

namespace meshnav::estimator::so3 {

/// [v]×: skew-symmetric matrix with [v]× w = v × w (common/skew.h).
using meshnav::skew;

/// Exp(φ) as a unit quaternion.
inline Eigen::Quaterniond expQuat(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  if (theta < 1e-12) {
    Eigen::Quaterniond q(1.0, 0.5 * phi.x(), 0.5 * phi.y(), 0.5 * phi.z());
    return q.normalized();
  }
  return Eigen::Quaterniond(Eigen::AngleAxisd(theta, phi / theta));
}

/// Exp(φ) as a rotation matrix.
inline Eigen::Matrix3d expMap(const Eigen::Vector3d& phi) { return expQuat(phi).toRotationMatrix(); }

/// Log(q): rotation vector of a unit quaternion, angle in [0, π].
inline Eigen::Vector3d logMap(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.w() < 0.0 ? Eigen::Quaterniond(-q_in.coeffs()) : q_in;
  const double n = q.vec().norm();
  if (n < 1e-12) return 2.0 * q.vec() / q.w();
  return 2.0 * std::atan2(n, q.w()) * q.vec() / n;
}

/// Log(R) of a rotation matrix.
inline Eigen::Vector3d logMap(const Eigen::Matrix3d& R) { return logMap(Eigen::Quaterniond(R)); }

/// Right Jacobian J_r(φ).
inline Eigen::Matrix3d rightJacobian(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d K = skew(phi);
  if (theta < 1e-6) return Eigen::Matrix3d::Identity() - 0.5 * K + K * K / 6.0;
  const double t2 = theta * theta;
  return Eigen::Matrix3d::Identity() - (1.0 - std::cos(theta)) / t2 * K +
         (theta - std::sin(theta)) / (t2 * theta) * K * K;
}

/// Heading ψ of a body attitude: the angle of its x axis projected on the horizontal plane of G.
inline double yawOf(const Eigen::Quaterniond& q_ItoG) {
  const Eigen::Matrix3d R = q_ItoG.toRotationMatrix();
  return std::atan2(R(1, 0), R(0, 0));
}

/// ψ_a − ψ_b wrapped to [−π, π] [rad].
inline double yawDifference(double psi_a, double psi_b) { return std::remainder(psi_a - psi_b, 2.0 * M_PI); }

/// ∂ψ/∂δθ for a local attitude error δθ (R = R̂ Exp(δθ)): a rotation about G's z is δθ along
/// n = R̂ᵀ e_z, so δψ = nᵀ δθ (to first order, exactly at zero pitch).
inline Eigen::Vector3d yawDirection(const Eigen::Quaterniond& q_ItoG) {
  return q_ItoG.conjugate() * Eigen::Vector3d::UnitZ();
}

/// Variance of the heading for a local attitude error of covariance Σ_θ: σ_ψ² = nᵀ Σ_θ n (≥ 0).
inline double yawVariance(const Eigen::Quaterniond& q_ItoG, const Eigen::Matrix3d& Sigma_theta) {
  const Eigen::Vector3d n = yawDirection(q_ItoG);
  return std::max(n.dot(Sigma_theta * n), 0.0);
}

}  // namespace meshnav::estimator::so3
