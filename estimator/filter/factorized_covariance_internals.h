#pragma once
/// @file factorized_covariance_internals.h
/// @brief Helpers shared by the two translation units of FactorizedCovariance
/// (factorized_covariance.cpp and factorized_covariance_dah_scalar.cpp). Internal to the filter.

#include <Eigen/Core>
#include <memory>
#include <utility>

namespace meshnav::estimator::factorized_internal {

/// An immutable shared factor (copy-on-write storage of S̄_ij).
inline std::shared_ptr<const Eigen::MatrixXd> shared(Eigen::MatrixXd m) {
  return std::make_shared<const Eigen::MatrixXd>(std::move(m));
}

/// max|A| · max|A⁻¹| as a cheap conditioning measure.
template <typename A, typename B>
double roughCondition(const Eigen::MatrixBase<A>& a, const Eigen::MatrixBase<B>& a_inv) {
  return a.cwiseAbs().maxCoeff() * a_inv.cwiseAbs().maxCoeff();
}

}  // namespace meshnav::estimator::factorized_internal
