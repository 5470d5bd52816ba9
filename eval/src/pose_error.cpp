#include "eval/pose_error.h"

#include <Eigen/Cholesky>
#include <cmath>

namespace meshnav::eval {

Eigen::Vector3d logSO3(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // shortest rotation: angle in [0, π]
  const Eigen::Vector3d v = q.vec();
  const double s = v.norm();
  if (s < 1e-12) return 2.0 * v;  // first order, exact in the limit
  const double angle = 2.0 * std::atan2(s, q.w());
  return v * (angle / s);
}

std::optional<double> nees(const Eigen::Vector3d& error, const Eigen::Matrix3d& cov) {
  if (!cov.allFinite() || !error.allFinite()) return std::nullopt;
  const Eigen::Matrix3d sym = 0.5 * (cov + cov.transpose());
  Eigen::LLT<Eigen::Matrix3d> llt(sym);
  if (llt.info() != Eigen::Success) return std::nullopt;
  // Reject numerically singular matrices (e.g. all zero except round-off).
  const Eigen::Vector3d d = llt.matrixLLT().diagonal();
  if (d.minCoeff() <= 1e-12 * std::max(1.0, d.maxCoeff())) return std::nullopt;
  return error.dot(llt.solve(error));
}

double PoseError::orientationErrorDeg() const { return theta_err_rad.norm() * 180.0 / M_PI; }

PoseError computePoseError(const PoseEstimate& est, const PoseSample& truth) {
  PoseError e;
  e.t = est.t;
  e.p_err_m = truth.p_IinG - est.p_IinG;
  e.theta_err_rad = logSO3(est.q_ItoG.normalized().conjugate() * truth.q_ItoG.normalized());
  e.sigma_p_m = est.cov_p_m2.diagonal().cwiseMax(0.0).cwiseSqrt();
  e.sigma_theta_rad = est.cov_theta_rad2.diagonal().cwiseMax(0.0).cwiseSqrt();
  e.nees_p = nees(e.p_err_m, est.cov_p_m2);
  e.nees_theta = nees(e.theta_err_rad, est.cov_theta_rad2);
  return e;
}

}  // namespace meshnav::eval
