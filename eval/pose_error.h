#pragma once
/// @file pose_error.h
/// @brief Error of one pose estimate against the true pose at the same instant.
///
/// Conventions (x̃ = x − x̂, "true minus estimate", as in the filter's error state):
///  - position error  p̃ = p_IinG(true) − p̂_IinG, in G [m];
///  - orientation error δθ = Log(R̂ᵀ R_true) ∈ so(3), local (in I) [rad], which is the error the
///    estimator's `cov_theta_rad2` describes (R_true = R̂ · Exp(δθ), types.h PoseEstimate);
///    its angle |δθ| equals the rotation angle of R_trueᵀ R̂ [rad].
///  - NEES: ε_p = p̃ᵀ P_p⁻¹ p̃ and ε_θ = δθᵀ P_θ⁻¹ δθ, each χ²(3) for a consistent filter.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

#include "common/types.h"

namespace meshnav::eval {

/// SO(3) logarithm: rotation vector of `q` (angle in [0, π]) [rad].
Eigen::Vector3d logSO3(const Eigen::Quaterniond& q);

/// Normalized estimation error squared x̃ᵀ P⁻¹ x̃; nullopt when P is not positive definite.
std::optional<double> nees(const Eigen::Vector3d& error, const Eigen::Matrix3d& cov);

/// Error of one associated estimate.
struct PoseError {
  Timestamp t;
  Eigen::Vector3d p_err_m = Eigen::Vector3d::Zero();        ///< p̃ in G [m]
  Eigen::Vector3d theta_err_rad = Eigen::Vector3d::Zero();  ///< δθ in I [rad]
  Eigen::Vector3d sigma_p_m = Eigen::Vector3d::Zero();      ///< √diag(P_p) [m]
  Eigen::Vector3d sigma_theta_rad = Eigen::Vector3d::Zero();///< √diag(P_θ) [rad]
  std::optional<double> nees_p;      ///< nullopt: position covariance not positive definite
  std::optional<double> nees_theta;  ///< nullopt: orientation covariance not positive definite
  bool flying = true;                ///< not landed at t (true when the flight state is unknown)

  double positionErrorNorm() const { return p_err_m.norm(); }
  /// Rotation angle of R_trueᵀ R̂ [deg].
  double orientationErrorDeg() const;
};

/// Error of `est` against the true pose `truth` (both valid at the same instant).
PoseError computePoseError(const PoseEstimate& est, const PoseSample& truth);

}  // namespace meshnav::eval
