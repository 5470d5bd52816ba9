#pragma once
/// @file imu_propagator.h
/// @brief IMU strapdown propagation of the nominal state and its discrete error transition.
///
/// Readings are held constant over [t, t + Δt] (ω̂ = ω_m − b̂_ω, â = a_m − b̂_a):
///   R' = R̂ Exp(ω̂ Δt),  a_G = R̂ Exp(ω̂ Δt/2) â + g,  v' = v + a_G Δt,  p' = p + v Δt + ½ a_G Δt²
/// with g = [0, 0, −|g|] in G. Φ is the exact Jacobian of this discrete map w.r.t. the error state
/// (R = R̂ Exp(δθ)):
///   δθ' = Exp(ω̂Δt)ᵀ δθ − J_r(ω̂Δt) Δt δb_ω
///   δv' = δv + Δt (A_θ δθ + A_bω δb_ω + A_ba δb_a),  δp' = δp + Δt δv + ½Δt² (…same…)
///   A_θ = −R_m [â]× E_½ᵀ,  A_bω = R_m [â]× J_r(ω̂Δt/2) Δt/2,  A_ba = −R_m,  R_m = R̂ E_½, E_½ = Exp(ω̂Δt/2)
/// Q from the noise densities: white noise held over the step (σ²/Δt) enters like the biases.

#include "estimator/core/estimator_options.h"
#include "estimator/core/imu_state.h"

namespace meshnav::estimator {

class ImuPropagator {
 public:
  /// `gravity_z_sign` −1: gravity along −z of G (z up, the convention); +1: an anchor frame whose z
  /// axis points down (EstimatorNode::checkGravityDirection).
  ImuPropagator(double gravity_m_s2, const ImuNoiseOptions& noise, double gravity_z_sign = -1.0)
      : gravity_m_s2_(gravity_m_s2), gravity_z_sign_(gravity_z_sign), noise_(noise) {}

  /// Propagates `x` over `dt_s` with constant readings; fills Φ and Q when non-null.
  void propagate(ImuState& x, const Eigen::Vector3d& acc_m_s2, const Eigen::Vector3d& gyro_rad_s, double dt_s,
                 ImuMatrix* Phi, ImuMatrix* Q) const;

  /// Gravity in G [m/s²].
  Eigen::Vector3d gravity_G() const { return {0.0, 0.0, gravity_z_sign_ * gravity_m_s2_}; }
  const ImuNoiseOptions& noise() const { return noise_; }

 private:
  double gravity_m_s2_;
  double gravity_z_sign_;
  ImuNoiseOptions noise_;
};

}  // namespace meshnav::estimator
