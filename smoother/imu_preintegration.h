#pragma once
/// @file imu_preintegration.h
/// @brief IMU increments between two instants, relative to the body at the first one, with their
/// first-order sensitivity to the biases and their covariance (on-manifold preintegration).
///
/// Between t_i and t_j, with readings ω̃, ã and bias linearization points b̄_ω, b̄_a, each sub-step
/// of length δ uses the readings' mean over it (linear interpolation between samples; a cut at an
/// instant between samples interpolates there), ω = ω̃ − b̄_ω, a = ã − b̄_a:
///   ΔR ← ΔR Exp(ω δ),  Δv ← Δv + ΔR_m a δ,  Δp ← Δp + Δv δ + ½ ΔR_m a δ²   (p, v before R),
/// ΔR_m = ΔR Exp(½ ω δ) the step's mid attitude (with ΔR at the step's start the velocity is off
/// by ½ ΔR [ωδ]× a δ per step, a 4 mm/s drift over 0.75 s of a 0.6 rad/s turn at 200 Hz).
/// The states then satisfy (g gravity in G, Δt = t_j − t_i)
///   R_j = R_i ΔR Exp(J_R^ω δb_ω),
///   v_j = v_i + g Δt + R_i (Δv + J_v^ω δb_ω + J_v^a δb_a),
///   p_j = p_i + v_i Δt + ½ g Δt² + R_i (Δp + J_p^ω δb_ω + J_p^a δb_a),
/// δb = b_i − b̄. Sensitivities per sub-step (ΔR_m in those of b_a, exact; first order in b_ω) (E = Exp(ω δ), J_r its right Jacobian):
///   J_p^a += J_v^a δ − ½ ΔR_m δ²,  J_p^ω += J_v^ω δ − ½ ΔR_m [a]× J_R^ω δ²,
///   J_v^a −= ΔR_m δ,  J_v^ω −= ΔR_m [a]× J_R^ω δ,  J_R^ω = Eᵀ J_R^ω − J_r δ.
/// Covariance of [δφ, δv, δp] (noise densities σ_ω, σ_a, discrete variance σ²/δ per sub-step):
///   Σ ← A Σ Aᵀ + B_ω (σ_ω²/δ) B_ωᵀ + B_a (σ_a²/δ) B_aᵀ,
///   A = [[Eᵀ, 0, 0], [−ΔR[a]×δ, I, 0], [−½ΔR[a]×δ², Iδ, I]],  B_ω = [J_r δ; 0; 0],
///   B_a = [0; ΔR δ; ½ ΔR δ²].
/// Derivation and the smoother that uses it: docs/smoother.md.

#include <Eigen/Core>
#include <vector>

#include "common/types.h"

namespace meshnav::smoother {

/// The increments of one span.
struct ImuIncrement {
  double dt_s = 0.0;                                        ///< Δt [s]
  Eigen::Matrix3d dR = Eigen::Matrix3d::Identity();         ///< ΔR (I_j relative to I_i)
  Eigen::Vector3d dv = Eigen::Vector3d::Zero();             ///< Δv in I_i [m/s]
  Eigen::Vector3d dp = Eigen::Vector3d::Zero();             ///< Δp in I_i [m]
  Eigen::Matrix3d dR_dbg = Eigen::Matrix3d::Zero();         ///< J_R^ω [s]
  Eigen::Matrix3d dv_dbg = Eigen::Matrix3d::Zero(), dv_dba = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d dp_dbg = Eigen::Matrix3d::Zero(), dp_dba = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 9, 9> cov = Eigen::Matrix<double, 9, 9>::Zero();  ///< of [δφ, δv, δp]
  Eigen::Vector3d bg_lin = Eigen::Vector3d::Zero();         ///< b̄_ω [rad/s]
  Eigen::Vector3d ba_lin = Eigen::Vector3d::Zero();         ///< b̄_a [m/s²]
};

/// IMU noise densities of the increments' covariance. A sub-step between two samples more than
/// `max_dt_s` apart (an IMU gap) runs on readings interpolated across the gap, whose error is
/// modelled as white noise of the gap densities (the estimator's imu.gap_sigma_*; docs/robustness.md,
/// "IMU gaps") on top of the sensor's.
struct ImuNoiseDensities {
  double acc = 0.02;         ///< σ_a [m/s²/√Hz]
  double gyro = 0.002;       ///< σ_ω [rad/s/√Hz]
  double max_dt_s = 0.0;     ///< samples farther apart are a gap [s]; 0: no gap model
  double gap_acc = 1.0;      ///< [m/s²/√s]
  double gap_gyro = 0.0;     ///< [rad/s/√s]
};

/// Integrates `imu` (sorted by time, covering [t0, t1]) from t0 to t1 at the given biases.
/// Throws std::invalid_argument when the samples do not cover the span or t1 < t0.
ImuIncrement preintegrate(const std::vector<ImuSample>& imu, Timestamp t0, Timestamp t1, const Eigen::Vector3d& bg,
                          const Eigen::Vector3d& ba, const ImuNoiseDensities& noise);

/// The reading at `t` interpolated linearly between the samples around it (clamped at the ends).
ImuSample interpolateImu(const std::vector<ImuSample>& imu, Timestamp t);

}  // namespace meshnav::smoother
