#pragma once
/// @file height_model.h
/// @brief Downward laser rangefinder over a flat floor at z = 0 in G, with the sensor's bias
/// instance b_H. The beam points along −z of the body (I, z up); the sensor sits at p_IH in I:
///   s = p_IinG + R_ItoG p_IH          (sensor position in G)
///   c = e_zᵀ R_ItoG e_z              (cosine of the tilt of the body's z axis)
///   h(x) = s_z / c + b_H             (tilt-corrected: the beam's length to the floor)
///   h(x) = s_z + b_H                 (without tilt correction)
/// Jacobians (R = R̂ Exp(δθ), so δR ≈ R̂ [δθ]×):
///   ∂s_z/∂δp = e_zᵀ,  ∂s_z/∂δθ = −e_zᵀ R̂ [p_IH]×,  ∂c/∂δθ = −e_zᵀ R̂ [e_z]×,
///   ∂h/∂δp = e_zᵀ / c,  ∂h/∂δθ = (∂s_z/∂δθ) / c − s_z (∂c/∂δθ) / c²,  ∂h/∂δb_H = 1.
/// The prediction is only meaningful while the beam points down (c > 0): `valid` says whether
/// the tilt stays within `max_tilt_rad`.

#include <Eigen/Core>
#include <cmath>

#include "estimator/core/linearization.h"
#include "estimator/core/nominal_state.h"
#include "estimator/height/height_measurement.h"

namespace meshnav::estimator {

class HeightModel {
 public:
  HeightModel(const Eigen::Vector3d& p_IH, bool tilt_correction, double max_tilt_rad)
      : p_IH_(p_IH), tilt_correction_(tilt_correction), min_cos_tilt_(std::cos(max_tilt_rad)) {}
  /// False while the body is tilted beyond the limit (the beam may miss the floor below).
  bool valid(const NominalState& x) const;
  /// Predicted range h(x̂) [m] (the sensor's bias must be in `x`).
  double predict(const HeightMeasurement& z, const NominalState& x) const;
  /// Residual and Jacobian blocks {imu id → 1×15, height id → 1×1}.
  Linearization linearize(const HeightMeasurement& z, const NominalState& x) const;

 private:
  double cosTilt(const NominalState& x) const;
  Eigen::Vector3d p_IH_;
  bool tilt_correction_ = true;
  double min_cos_tilt_ = 0.0;
};

}  // namespace meshnav::estimator
