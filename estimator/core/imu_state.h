#pragma once
/// @file imu_state.h
/// @brief Nominal IMU state x_I = [p_IinG, v_IinG, q_ItoG, b_ω, b_a] (paper eq. IMU-state) and the
/// layout of its 15-dim error state δx_I = [δp, δv, δθ, δb_ω, δb_a] with
/// p = p̂ + δp, v = v̂ + δv, R = R̂ · Exp(δθ) (local, in I), b = b̂ + δb.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimator/core/so3.h"

namespace meshnav::estimator {

/// Named offsets inside the IMU error state.
struct ImuErr {
  static constexpr int kP = 0;       ///< δp_IinG [m]
  static constexpr int kV = 3;       ///< δv_IinG [m/s]
  static constexpr int kTheta = 6;   ///< δθ (local) [rad]
  static constexpr int kBg = 9;      ///< δb_ω [rad/s]
  static constexpr int kBa = 12;     ///< δb_a [m/s²]
  static constexpr int kDim = 15;
};

using ImuVector = Eigen::Matrix<double, ImuErr::kDim, 1>;
using ImuMatrix = Eigen::Matrix<double, ImuErr::kDim, ImuErr::kDim>;

struct ImuState {
  Eigen::Vector3d p_IinG = Eigen::Vector3d::Zero();         ///< [m]
  Eigen::Vector3d v_IinG = Eigen::Vector3d::Zero();         ///< [m/s]
  Eigen::Quaterniond q_ItoG = Eigen::Quaterniond::Identity();
  Eigen::Vector3d bias_gyro_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d bias_acc_m_s2 = Eigen::Vector3d::Zero();

  /// x ← x ⊞ δx.
  template <typename Derived>
  void boxplus(const Eigen::MatrixBase<Derived>& dx) {
    p_IinG += dx.template segment<3>(ImuErr::kP);
    v_IinG += dx.template segment<3>(ImuErr::kV);
    q_ItoG = (q_ItoG * so3::expQuat(dx.template segment<3>(ImuErr::kTheta))).normalized();
    bias_gyro_rad_s += dx.template segment<3>(ImuErr::kBg);
    bias_acc_m_s2 += dx.template segment<3>(ImuErr::kBa);
  }
  /// δx = x ⊟ x̂ (this = x, `ref` = x̂).
  ImuVector boxminus(const ImuState& ref) const {
    ImuVector d;
    d.segment<3>(ImuErr::kP) = p_IinG - ref.p_IinG;
    d.segment<3>(ImuErr::kV) = v_IinG - ref.v_IinG;
    d.segment<3>(ImuErr::kTheta) = so3::logMap(ref.q_ItoG.conjugate() * q_ItoG);
    d.segment<3>(ImuErr::kBg) = bias_gyro_rad_s - ref.bias_gyro_rad_s;
    d.segment<3>(ImuErr::kBa) = bias_acc_m_s2 - ref.bias_acc_m_s2;
    return d;
  }
};

}  // namespace meshnav::estimator
