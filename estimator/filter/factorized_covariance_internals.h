#pragma once
/// @file factorized_covariance_internals.h
/// @brief Helpers shared by the two translation units of FactorizedCovariance
/// (factorized_covariance.cpp and factorized_covariance_dah.cpp). Internal to the filter.

#include <Eigen/Core>
#include <memory>
#include <utility>

#include "estimator/filter/instance_belief.h"

namespace meshnav::estimator::factorized_internal {

/// A shared factor (copy-on-write storage of S̄_ij). Created non-const so that its only owner may
/// write it in place (writableFactor); read-only for everyone else.
inline std::shared_ptr<const Eigen::MatrixXd> shared(Eigen::MatrixXd m) {
  return std::make_shared<Eigen::MatrixXd>(std::move(m));
}

/// Storage for a new S̄ (rows × cols) in `slot`: the matrix it holds when no one else does (no
/// snapshot or partner shares it: the dictionary holding `slot` is this instance's own), else a
/// new one. Every S̄ is made by shared(), so the object is not const.
inline Eigen::MatrixXd& writableFactor(std::shared_ptr<const Eigen::MatrixXd>& slot, Eigen::Index rows,
                                       Eigen::Index cols) {
  if (slot && slot.use_count() == 1) {
    auto& m = const_cast<Eigen::MatrixXd&>(*slot);
    m.resize(rows, cols);
    return m;
  }
  auto m = std::make_shared<Eigen::MatrixXd>(rows, cols);
  Eigen::MatrixXd& ref = *m;
  slot = std::move(m);
  return ref;
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

}  // namespace meshnav::estimator::factorized_internal
