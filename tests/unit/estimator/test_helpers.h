#pragma once
/// @file test_helpers.h
/// @brief Numerical differentiation over the error state for the estimator's unit tests.

#include <Eigen/Core>
#include <functional>

#include "estimator/core/linearization.h"
#include "estimator/core/nominal_state.h"

namespace meshnav::estimator::test {

/// A random but reasonable nominal state with an IMU, a baro bias and two estimated anchors.
inline NominalState randomState(unsigned seed) {
  std::srand(seed);
  NominalState x;
  x.imu_id = 1;
  x.imu.p_IinG = Eigen::Vector3d::Random() * 2.0 + Eigen::Vector3d(0, 0, 3);
  x.imu.v_IinG = Eigen::Vector3d::Random();
  x.imu.q_ItoG = Eigen::Quaterniond(Eigen::Vector4d::Random()).normalized();
  x.imu.bias_gyro_rad_s = Eigen::Vector3d::Random() * 0.01;
  x.imu.bias_acc_m_s2 = Eigen::Vector3d::Random() * 0.1;
  x.values<BaroBiasKind>()[2] = 0.3;
  x.values<AnchorKind>()[106].p_AinG = Eigen::Vector3d(-1.772, 0.943, 3.256);
  x.values<AnchorKind>()[107].p_AinG = Eigen::Vector3d(-2.021, 1.814, 1.732);
  return x;
}

/// Layout IMU, baro 2, anchors 106, 107.
inline StateLayout layoutOf(const NominalState& x) {
  StateLayout l;
  l.add(x.imu_id, kindOf<ImuKind>);
  for (const auto& [id, b] : x.values<BaroBiasKind>()) l.add(id, kindOf<BaroBiasKind>);
  for (const auto& [id, a] : x.values<AnchorKind>()) l.add(id, kindOf<AnchorKind>);
  return l;
}

/// Central differences of h(x ⊞ δx) w.r.t. δx (stacked over `layout`).
inline Eigen::MatrixXd numericalJacobian(const NominalState& x, const StateLayout& layout,
                                         const std::function<Eigen::VectorXd(const NominalState&)>& h,
                                         double eps = 1e-6) {
  const Eigen::VectorXd h0 = h(x);
  Eigen::MatrixXd J(h0.size(), layout.dim());
  for (int i = 0; i < layout.dim(); ++i) {
    Eigen::VectorXd dx = Eigen::VectorXd::Zero(layout.dim());
    dx(i) = eps;
    NominalState xp = x, xm = x;
    xp.boxplus(layout, dx);
    xm.boxplus(layout, -dx);
    J.col(i) = (h(xp) - h(xm)) / (2.0 * eps);
  }
  return J;
}

/// Stacks the named blocks of `lin` into a full H over `layout` (zeros elsewhere).
inline Eigen::MatrixXd stack(const Linearization& lin, const StateLayout& layout) {
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(lin.dim(), layout.dim());
  for (const auto& b : lin.blocks) {
    const StateBlock& sb = layout.at(b.id);
    H.block(0, sb.offset, lin.dim(), sb.dim) = b.H;
  }
  return H;
}

}  // namespace meshnav::estimator::test
