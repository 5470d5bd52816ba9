#pragma once
/// @file imu_kind.h
/// @brief Instance kind of the IMU, the body (estimator/core/kind_traits.h): x_I and its 15-dim
/// error state, held in NominalState::imu; its process noise comes from the propagator.

#include <Eigen/Core>

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
};

}  // namespace meshnav::estimator
