#pragma once
/// @file imu_kind.h
/// @brief Instance kind of the IMU, the body (estimator/core/kind_traits.h): x_I and its 15-dim
/// error state, held in NominalState::imu; its process noise comes from the propagator.

#include <Eigen/Core>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "estimator/core/estimator_options.h"
#include "estimator/core/imu_state.h"
#include "estimator/core/kind_traits.h"

namespace meshnav::estimator {

struct ImuKind {
  static constexpr const char* kName = "imu";
  static constexpr int kDim = ImuErr::kDim;
  static constexpr bool kBody = true;
  using Value = ImuState;
  static void boxplus(Value& x, const Eigen::Ref<const Eigen::VectorXd>& dx) {
    x.boxplus(dx.template head<ImuErr::kDim>());
  }
  static Eigen::VectorXd boxminus(const Value& x, const Value& ref) { return x.boxminus(ref); }
  static void check(SensorId id, const Value&, const Eigen::MatrixXd& cov) { requireBlockSize(kName, id, cov, kDim); }
  static double randomWalk(const EstimatorOptions&) { return 0.0; }
  static Eigen::MatrixXd keptCovariance(const Eigen::MatrixXd& cov, const EstimatorOptions&) { return cov; }
  static Restart restart(const EstimatorOptions&) { return Restart::kBody; }
  /// [p_IinG, v_IinG, q_ItoG (x, y, z, w), b_ω, b_a]: 16 numbers; the quaternion must be of unit
  /// norm within 1e-3 (it is normalized).
  static Eigen::VectorXd toVector(const Value& s) {
    Eigen::VectorXd x(16);
    x << s.p_IinG, s.v_IinG, s.q_ItoG.coeffs(), s.bias_gyro_rad_s, s.bias_acc_m_s2;
    return x;
  }
  static std::vector<SensorId> peersOf(const Value&) { return {}; }
  static Value fromVector(const Eigen::VectorXd& x, const std::vector<SensorId>& peers) {
    requireVectorSize(kName, x.size(), 16);
    if (!peers.empty()) throw std::invalid_argument("imu: has no peers");
    Value s;
    s.p_IinG = x.segment<3>(0);
    s.v_IinG = x.segment<3>(3);
    s.q_ItoG.coeffs() = x.segment<4>(6);
    if (std::abs(s.q_ItoG.norm() - 1.0) > 1e-3) throw std::invalid_argument("imu: q_ItoG is not a unit quaternion");
    s.q_ItoG.normalize();
    s.bias_gyro_rad_s = x.segment<3>(10);
    s.bias_acc_m_s2 = x.segment<3>(13);
    return s;
  }
};

}  // namespace meshnav::estimator
