#include "estimator/imu/imu_propagator.h"

namespace meshnav::estimator {

using Eigen::Matrix3d;
using Eigen::Vector3d;

void ImuPropagator::propagate(ImuState& x, const Vector3d& acc_m_s2, const Vector3d& gyro_rad_s, double dt,
                              ImuMatrix* Phi, ImuMatrix* Q) const {
  const Vector3d w_hat = gyro_rad_s - x.bias_gyro_rad_s;
  const Vector3d a_hat = acc_m_s2 - x.bias_acc_m_s2;
  const Matrix3d R = x.q_ItoG.toRotationMatrix();
  const Vector3d phi = w_hat * dt;
  const Matrix3d E_half = so3::expMap(0.5 * phi);
  const Matrix3d R_mid = R * E_half;
  const Vector3d a_G = R_mid * a_hat + gravity_G();

  if (Phi) {
    const Matrix3d I3 = Matrix3d::Identity();
    const Matrix3d A_theta = -R_mid * so3::skew(a_hat) * E_half.transpose();
    const Matrix3d A_bg = R_mid * so3::skew(a_hat) * so3::rightJacobian(0.5 * phi) * (0.5 * dt);
    const Matrix3d A_ba = -R_mid;
    const double h = 0.5 * dt * dt;
    ImuMatrix& F = *Phi;
    F.setIdentity();
    F.block<3, 3>(ImuErr::kP, ImuErr::kV) = I3 * dt;
    F.block<3, 3>(ImuErr::kP, ImuErr::kTheta) = A_theta * h;
    F.block<3, 3>(ImuErr::kP, ImuErr::kBg) = A_bg * h;
    F.block<3, 3>(ImuErr::kP, ImuErr::kBa) = A_ba * h;
    F.block<3, 3>(ImuErr::kV, ImuErr::kTheta) = A_theta * dt;
    F.block<3, 3>(ImuErr::kV, ImuErr::kBg) = A_bg * dt;
    F.block<3, 3>(ImuErr::kV, ImuErr::kBa) = A_ba * dt;
    F.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) = so3::expMap(phi).transpose();
    F.block<3, 3>(ImuErr::kTheta, ImuErr::kBg) = -so3::rightJacobian(phi) * dt;
  }
  if (Q) {
    const double sa2 = noise_.acc_noise_density * noise_.acc_noise_density;
    const double sg2 = noise_.gyro_noise_density * noise_.gyro_noise_density;
    const double sba2 = noise_.acc_bias_rw * noise_.acc_bias_rw;
    const double sbg2 = noise_.gyro_bias_rw * noise_.gyro_bias_rw;
    const Matrix3d I3 = Matrix3d::Identity();
    ImuMatrix& q = *Q;
    q.setZero();
    q.block<3, 3>(ImuErr::kP, ImuErr::kP) = I3 * (0.25 * sa2 * dt * dt * dt);
    q.block<3, 3>(ImuErr::kP, ImuErr::kV) = I3 * (0.5 * sa2 * dt * dt);
    q.block<3, 3>(ImuErr::kV, ImuErr::kP) = I3 * (0.5 * sa2 * dt * dt);
    q.block<3, 3>(ImuErr::kV, ImuErr::kV) = I3 * (sa2 * dt);
    q.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) = I3 * (sg2 * dt);
    q.block<3, 3>(ImuErr::kBg, ImuErr::kBg) = I3 * (sbg2 * dt);
    q.block<3, 3>(ImuErr::kBa, ImuErr::kBa) = I3 * (sba2 * dt);
  }

  x.p_IinG += x.v_IinG * dt + 0.5 * a_G * dt * dt;
  x.v_IinG += a_G * dt;
  x.q_ItoG = (x.q_ItoG * so3::expQuat(phi)).normalized();
}

}  // namespace meshnav::estimator
