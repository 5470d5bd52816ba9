#pragma once
/// @file zupt_model.h
/// @brief Zero-velocity update (paper §III-A, "Zero Velocity Update"), a private IMU update:
///   z = 0 = h(x) + ν,  h(x) = [ a_m − b_a + Rᵀ g_G ;  ω_m − b_ω ;  v_IinG ]   (9 rows)
/// g_G = [0, 0, −|g|] (so Rᵀ g_G = −Rᵀ g_up, the paper's "−Rᵀg"). With R = R̂ Exp(δθ):
///   ∂h_a/∂δθ = [R̂ᵀ g_G]× = −[R̂ᵀ g_up]×,  ∂h_a/∂δb_a = −I,  ∂h_ω/∂δb_ω = −I,  ∂h_v/∂δv = I.

#include <Eigen/Core>

#include "estimator/core/linearization.h"
#include "estimator/core/nominal_state.h"
#include "estimator/zupt/zupt_measurement.h"

namespace meshnav::estimator {

class ZuptModel {
 public:
  static constexpr int kDim = 9;
  explicit ZuptModel(const Eigen::Vector3d& gravity_G) : g_G_(gravity_G) {}
  /// h(x̂) (9 rows).
  Eigen::Matrix<double, kDim, 1> predict(const ZuptMeasurement& z, const NominalState& x) const;
  /// Residual r = 0 − h(x̂) and the block {imu id → 9×15}.
  Linearization linearize(const ZuptMeasurement& z, const NominalState& x) const;

 private:
  Eigen::Vector3d g_G_;
};

}  // namespace meshnav::estimator
