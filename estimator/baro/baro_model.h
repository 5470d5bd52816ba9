#pragma once
/// @file baro_model.h
/// @brief Barometric height model (paper eq. barometric-height) with the baro's bias instance:
///   h(x) = (p_IinG + R_ItoG p_IP)_z + b_P
/// Jacobians (R = R̂ Exp(δθ)): ∂h/∂δp = e_zᵀ, ∂h/∂δθ = −e_zᵀ R̂ [p_IP]×, ∂h/∂δb_P = 1.

#include <Eigen/Core>

#include "estimator/baro/baro_measurement.h"
#include "estimator/core/linearization.h"
#include "estimator/core/nominal_state.h"

namespace meshnav::estimator {

class BaroModel {
 public:
  explicit BaroModel(const Eigen::Vector3d& p_IP) : p_IP_(p_IP) {}
  /// Predicted height h(x̂) [m] (the baro's bias must be in `x`).
  double predict(const BaroMeasurement& z, const NominalState& x) const;
  /// Residual and Jacobian blocks {imu id → 1×15, baro id → 1×1}.
  Linearization linearize(const BaroMeasurement& z, const NominalState& x) const;

 private:
  Eigen::Vector3d p_IP_;
};

}  // namespace meshnav::estimator
