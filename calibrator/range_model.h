#pragma once
/// @file range_model.h
/// @brief The range model of the calibration, its information matrix, the covariance of the
/// estimate and the Cramér–Rao bound (all plain Eigen; the Ceres code lives in nonlinear_refiner).
///
/// Model (paper eq. z_kl): z = β_R·d + γ_R + ν, d = ‖p_AinG − p_RinG‖. With u = (p_AinG − p_RinG)/d:
///   ∂z/∂p_AinG = β_R·uᵀ,  ∂z/∂γ_R = 1,  ∂z/∂β_R = d,  ∂z/∂p_RinG = −β_R·uᵀ.
/// The reference position is uncertain, so each range is weighted with its effective variance
///   σ_eff² = σ_d² + β_R²·uᵀ Σ_R u,
/// and the information of the unknowns is H = Σ_i J_iᵀ J_i / σ_eff,i² + H_prior, where the prior
/// (γ_R ~ N(γ̄, σ_γ²), β_R ~ N(β̄, σ_β²)) keeps γ of stationary references from absorbing
/// position information they do not have.

#include <Eigen/Core>
#include <vector>

#include "calibrator/calibration_problem.h"

namespace meshnav::calib {

/// Predicted range β·d + γ of observation i [m].
double predictRange(const CalibrationProblem& pb, const AnchorParams& x, int i);
/// σ_eff of observation i at x [m].
double effectiveSigma(const CalibrationProblem& pb, const AnchorParams& x, int i);
/// Stacked unknowns ↔ params.
Eigen::VectorXd stack(const CalibrationProblem& pb, const AnchorParams& x);
AnchorParams unstack(const CalibrationProblem& pb, const Eigen::VectorXd& v);

/// H = Σ_{i used} J_iᵀJ_i/σ_eff,i² (+ prior information when `with_priors`), over the stacked
/// unknowns. `use` selects observations (empty: all observations with a slot).
Eigen::MatrixXd informationMatrix(const CalibrationProblem& pb, const AnchorParams& x, const std::vector<bool>& use,
                                  bool with_priors);

/// Covariance of the estimate x over the observations `use`.
struct CovarianceEstimate {
  bool ok = false;
  Eigen::MatrixXd P;          ///< stacked covariance (scaled by s² when s² > 1 and enabled)
  double s2 = 1.0;            ///< whitened residual variance Σ r²/σ_eff² / (n − dim)
  int n = 0;
};
///
/// With `correlated_reference_fraction` c > 0, a common error δ ~ N(0, c·Σ̄_R) of the moving
/// references (Σ̄_R: mean position covariance of their used observations) is added: a shift δ
/// changes residual i by β_i u_iᵀ δ, hence the estimate by S δ with S = H⁻¹ Σ_i j_i β_i u_iᵀ / σ_eff,i²
/// (≈ [I; 0] for the position when only moving references carry geometry), so P += c·S Σ̄_R Sᵀ.
CovarianceEstimate estimateCovariance(const CalibrationProblem& pb, const AnchorParams& x,
                                      const std::vector<bool>& use, bool scale_by_residuals,
                                      double correlated_reference_fraction = 0.0);

/// Cramér–Rao bound of the same data: (H at the true parameters, with priors)⁻¹ over the stacked
/// unknowns. Returns an empty matrix when H is singular.
Eigen::MatrixXd cramerRaoBound(const CalibrationProblem& pb, const AnchorParams& truth);
/// √trace of the position block of the CRB [m] (the smallest achievable RMS position error);
/// NaN when singular.
double crbPositionRmse(const CalibrationProblem& pb, const AnchorParams& truth);

}  // namespace meshnav::calib
