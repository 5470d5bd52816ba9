#include "estimator/zupt/zupt_model.h"

namespace meshnav::estimator {

Eigen::Matrix<double, ZuptModel::kDim, 1> ZuptModel::predict(const ZuptMeasurement& z, const NominalState& x) const {
  Eigen::Matrix<double, kDim, 1> h;
  h.segment<3>(0) = z.acc_m_s2 - x.imu.bias_acc_m_s2 + x.imu.q_ItoG.conjugate() * g_G_;
  h.segment<3>(3) = z.gyro_rad_s - x.imu.bias_gyro_rad_s;
  h.segment<3>(6) = x.imu.v_IinG;
  return h;
}

Linearization ZuptModel::linearize(const ZuptMeasurement& z, const NominalState& x) const {
  Linearization lin;
  lin.residual = -predict(z, x);
  Eigen::VectorXd sig(kDim);
  sig << Eigen::Vector3d::Constant(z.sigma_acc_m_s2), Eigen::Vector3d::Constant(z.sigma_gyro_rad_s),
      Eigen::Vector3d::Constant(z.sigma_vel_m_s);
  lin.R = sig.array().square().matrix().asDiagonal();
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(kDim, ImuErr::kDim);
  const Eigen::Vector3d g_I = x.imu.q_ItoG.conjugate() * g_G_;
  H.block<3, 3>(0, ImuErr::kTheta) = so3::skew(g_I);
  H.block<3, 3>(0, ImuErr::kBa) = -Eigen::Matrix3d::Identity();
  H.block<3, 3>(3, ImuErr::kBg) = -Eigen::Matrix3d::Identity();
  H.block<3, 3>(6, ImuErr::kV) = Eigen::Matrix3d::Identity();
  lin.blocks.push_back({x.imu_id, std::move(H)});
  return lin;
}

}  // namespace meshnav::estimator
