#include "controller/position_controller.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace meshnav::controller {

namespace {
constexpr double kGravity_m_s2 = 9.81;

Eigen::Vector3d vee(const Eigen::Matrix3d& S) { return {S(2, 1), S(0, 2), S(1, 0)}; }

/// Scales the horizontal part of `v` down to at most `max`.
void limitXy(Eigen::Vector3d& v, double max) {
  const double n = v.head<2>().norm();
  if (n > max && n > 0.0) v.head<2>() *= max / n;
}

/// R_d with body z along `f` and heading `yaw`.
Eigen::Matrix3d desiredAttitude(const Eigen::Vector3d& f, double yaw) {
  const Eigen::Vector3d b3 = f.normalized();
  const Eigen::Vector3d c1(std::cos(yaw), std::sin(yaw), 0.0);
  Eigen::Vector3d b2 = b3.cross(c1);
  if (b2.norm() < 1e-6) b2 = b3.cross(Eigen::Vector3d::UnitX());
  b2.normalize();
  Eigen::Matrix3d R;
  R.col(0) = b2.cross(b3);
  R.col(1) = b2;
  R.col(2) = b3;
  return R;
}
}  // namespace

PositionController::PositionController(const ControllerOptions& options) : options_(options) {}

void PositionController::reset() { integral_.setZero(); }

double PositionController::hoverThrust() const { return kGravity_m_s2 + integral_.z(); }

double PositionController::clampThrust(double t) const { return std::clamp(t, 0.0, options_.max_thrust_m_s2); }

Eigen::Vector3d PositionController::attitudeRates(const Eigen::Matrix3d& R, const Eigen::Matrix3d& R_d) const {
  const Eigen::Vector3d e_R = 0.5 * vee(R_d.transpose() * R - R.transpose() * R_d);
  Eigen::Vector3d w(-options_.k_tilt_per_s * e_R.x(), -options_.k_tilt_per_s * e_R.y(), -options_.k_yaw_per_s * e_R.z());
  for (int i = 0; i < 3; ++i) w(i) = std::clamp(w(i), -options_.max_rate_rad_s, options_.max_rate_rad_s);
  return w;
}

ControlCommand PositionController::compute(const Eigen::Vector3d& p, const Eigen::Vector3d& v,
                                           const Eigen::Matrix3d& R, const Setpoint& sp, double dt_s) {
  const ControllerOptions& o = options_;
  // Position → velocity.
  Eigen::Vector3d v_c = sp.v_IinG;
  v_c.head<2>() += o.kp_xy_per_s * (sp.p_IinG - p).head<2>();
  if (sp.hold_z) v_c.z() += o.kp_z_per_s * (sp.p_IinG.z() - p.z());
  limitXy(v_c, o.max_speed_xy_m_s);
  v_c.z() = std::clamp(v_c.z(), -o.max_speed_z_m_s, o.max_speed_z_m_s);
  // Velocity → acceleration (PI).
  const Eigen::Vector3d e_v = v_c - v;
  const Eigen::Vector3d ki(o.ki_xy_per_s2, o.ki_xy_per_s2, o.ki_z_per_s2);
  integral_ += ki.cwiseProduct(e_v) * dt_s;
  integral_ = integral_.cwiseMax(-o.integral_limit_m_s2).cwiseMin(o.integral_limit_m_s2);
  const Eigen::Vector3d kv(o.kv_xy_per_s, o.kv_xy_per_s, o.kv_z_per_s);
  Eigen::Vector3d a_c = sp.a_IinG + kv.cwiseProduct(e_v) + integral_;
  limitXy(a_c, o.max_acc_xy_m_s2);
  // Thrust vector with the tilt limit.
  Eigen::Vector3d f = a_c + Eigen::Vector3d(0.0, 0.0, kGravity_m_s2);
  f.z() = std::max(f.z(), 0.2 * kGravity_m_s2);  // never command a dive
  limitXy(f, f.z() * std::tan(o.max_tilt_deg * std::numbers::pi / 180.0));
  const Eigen::Matrix3d R_d = desiredAttitude(f, sp.yaw_rad);
  ControlCommand c;
  c.thrust_m_s2 = clampThrust(f.dot(R.col(2)));
  c.w_IinI = attitudeRates(R, R_d);
  return c;
}

ControlCommand PositionController::levelDescent(const Eigen::Matrix3d& R, double yaw_rad,
                                                double descent_acc_m_s2) const {
  ControlCommand c;
  const Eigen::Matrix3d R_d = desiredAttitude(Eigen::Vector3d::UnitZ(), yaw_rad);
  c.w_IinI = attitudeRates(R, R_d);
  c.thrust_m_s2 = clampThrust((hoverThrust() - descent_acc_m_s2) / std::max(R(2, 2), 0.5));
  return c;
}

}  // namespace meshnav::controller
