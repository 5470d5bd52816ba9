#include "estimator/baro/baro_model.h"

namespace meshnav::estimator {

double BaroModel::predict(const BaroMeasurement& z, const NominalState& x) const {
  return (x.imu.p_IinG + x.imu.q_ItoG * p_IP_).z() + x.values<BaroBiasKind>().at(z.baro_id);
}

Linearization BaroModel::linearize(const BaroMeasurement& z, const NominalState& x) const {
  Linearization lin;
  lin.residual = Eigen::VectorXd::Constant(1, z.height_m - predict(z, x));
  lin.R = Eigen::MatrixXd::Constant(1, 1, z.sigma_m * z.sigma_m);
  Eigen::MatrixXd H_imu = Eigen::MatrixXd::Zero(1, ImuErr::kDim);
  H_imu(0, ImuErr::kP + 2) = 1.0;
  const Eigen::Matrix3d R = x.imu.q_ItoG.toRotationMatrix();
  H_imu.block<1, 3>(0, ImuErr::kTheta) = -(R * so3::skew(p_IP_)).row(2);
  lin.blocks.push_back({x.imu_id, std::move(H_imu)});
  lin.blocks.push_back({z.baro_id, Eigen::MatrixXd::Ones(1, 1)});
  return lin;
}

}  // namespace meshnav::estimator
