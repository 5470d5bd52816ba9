#pragma once
/// @file factorized_covariance_internals.h
/// @brief Helpers shared by the two translation units of FactorizedCovariance
/// (factorized_covariance.cpp and factorized_covariance_dah_scalar.cpp). Internal to the filter.

#include <Eigen/Core>
#include <memory>
#include <utility>

#include "estimator/filter/instance_belief.h"

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

/// Largest instance handled with stack storage (the IMU).
constexpr int kMaxInstanceDim = 15;
/// One instance's matrices (factors, L_i⁻¹) without heap allocation.
using InstMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxInstanceDim, kMaxInstanceDim>;

/// DAH correction of participant `b` of a joint scalar update with u = its rows of Σ_PP hᵀ and
/// s = h Σ_PP hᵀ + R: L_i ← (Σ_ii' Σ_ii⁻¹) L_i = (I − u wᵀ / s) L_i, w = Σ_ii⁻¹ u (b.Sigma must still
/// be Σ_ii); fixed-size kernels for the IMU and 3-state anchors (factorized_covariance_dah_scalar.cpp).
void foldScalarCorrection(InstanceBelief& b, const Eigen::Ref<const Eigen::VectorXd>& u, double s);

/// L_i⁻¹ into `out`; false when L_i must be re-normalized instead (old, not finite, badly conditioned).
template <typename Out>
bool invertPendingFactor(const InstanceBelief& b, Out& out);

}  // namespace meshnav::estimator::factorized_internal
