#include "estimator/height/height_model.h"

#include "estimator/core/so3.h"

namespace meshnav::estimator {

double HeightModel::cosTilt(const NominalState& x) const {
  return tilt_correction_ ? x.imu.q_ItoG.toRotationMatrix()(2, 2) : 1.0;
}

bool HeightModel::valid(const NominalState& x) const {
  return x.imu.q_ItoG.toRotationMatrix()(2, 2) >= min_cos_tilt_;
}

double HeightModel::predict(const HeightMeasurement& z, const NominalState& x) const {
  const double s_z = (x.imu.p_IinG + x.imu.q_ItoG * p_IH_).z();
  return s_z / cosTilt(x) + x.values<HeightBiasKind>().at(z.height_id);
}

Linearization HeightModel::linearize(const HeightMeasurement& z, const NominalState& x) const {
  const Eigen::Matrix3d R = x.imu.q_ItoG.toRotationMatrix();
  const double c = cosTilt(x);
  const double s_z = (x.imu.p_IinG + R * p_IH_).z();
  Linearization lin;
  lin.residual = Eigen::VectorXd::Constant(1, z.range_m - predict(z, x));
  lin.R = Eigen::MatrixXd::Constant(1, 1, z.sigma_m * z.sigma_m);
  Eigen::MatrixXd H_imu = Eigen::MatrixXd::Zero(1, ImuErr::kDim);
  H_imu(0, ImuErr::kP + 2) = 1.0 / c;
  Eigen::RowVector3d H_theta = -(R * so3::skew(p_IH_)).row(2) / c;
  if (tilt_correction_) H_theta += s_z / (c * c) * (R * so3::skew(Eigen::Vector3d::UnitZ())).row(2);
  H_imu.block<1, 3>(0, ImuErr::kTheta) = H_theta;
  lin.blocks.push_back({x.imu_id, std::move(H_imu)});
  lin.blocks.push_back({z.height_id, Eigen::MatrixXd::Ones(1, 1)});
  return lin;
}

}  // namespace meshnav::estimator
