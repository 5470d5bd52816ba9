#pragma once
/// @file optimal_double_solver.h
/// @brief Linear step of the calibration: the optimal double method (paper §III-C-1).
///
/// Squaring z = d + γ_R + ν (β = 1 here) and differencing two ranges of the same moving reference R
/// at reference positions p₁, p₂ eliminates ‖p_AinG‖² and γ_R²:
///   2(p₁ − p₂)ᵀ p_AinG − 2 ρ₁₂ γ_R = ‖p₁‖² − ‖p₂‖² − (z₁² − z₂²) + (σ₁² − σ₂²) − (tr Σ₁ − tr Σ₂),
/// one row of A x = b in x = [p_AinG, γ_R of every moving reference]. The γ regressor ρ₁₂ is
/// z₁ − z₂ in the first pass (the paper's form). Its noise ν₁ − ν₂ is correlated with the noise of b
/// (2d₁ν₁ − 2d₂ν₂), an errors-in-variables bias of order σ_d²·d/Δd² on γ and p. Passes 2… replace it by
/// the predicted difference d̂₁ − d̂₂ from the previous pass, which is exact at the true anchor
/// position (z₁² − z₂² = ‖p₁‖² − ‖p₂‖² − 2(p₁ − p₂)ᵀp_AinG + 2γ(d₁ − d₂) + noise) and carries no
/// measurement noise of the row: the estimate is then unbiased to first order. The last two terms
/// of b remove the means of ν₁² − ν₂² and of the reference-position noise in ‖p₁‖² − ‖p₂‖².
/// Rows are weighted with 1/var(b) = 1/(4(σ₁²ẑ₁² + σ₂²ẑ₂²)).
///
/// Pairs: each reference's time-sorted ranges are paired disjointly (each range in one row, so rows
/// are independent) as i ↔ i + k inside blocks of 2k; k runs over n/2, n/4, …, 1 and the k whose rows
/// give the smallest trace of the position covariance (after marginalising γ_R) is taken. On a
/// flight this pairs ranges taken far apart (large ‖p₁ − p₂‖, well-spread directions), never the
/// adjacent ones whose difference is mostly noise.
///
/// Stationary references (p₁ = p₂) give empty rows: their γ_R is set afterwards to the mean of
/// z − ‖p_AinG − p_RinG‖ (they carry no position information without a prior).

#include <string>
#include <utility>
#include <vector>

#include "calibrator/calibration_problem.h"

namespace meshnav::calib {

struct LinearSolution {
  bool ok = false;
  std::string reason;
  AnchorParams params;  ///< β at the prior means
  int n_rows = 0;
};

class OptimalDoubleSolver {
 public:
  explicit OptimalDoubleSolver(const CalibratorOptions& options) : options_(options) {}

  /// Solves on the observations `subset` (indices into pb.observations() with a slot; empty: all).
  LinearSolution solve(const CalibrationProblem& pb, const std::vector<int>& subset = {}) const;

  /// Disjoint pairs (i, j) among the time-sorted indices `idx` of one reference, chosen as
  /// described above from the γ regressors `rho` (per entry of idx) and row weights.
  static std::vector<std::pair<int, int>> selectPairs(const CalibrationProblem& pb, const std::vector<int>& idx,
                                                      const std::vector<double>& rho,
                                                      const std::vector<double>& var_half);

 private:
  CalibratorOptions options_;
};

}  // namespace meshnav::calib
