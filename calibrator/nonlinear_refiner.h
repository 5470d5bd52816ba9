#pragma once
/// @file nonlinear_refiner.h
/// @brief Nonlinear refinement of the calibration (paper §III-C-2): Levenberg–Marquardt (Ceres) on
///   min_x ½ Σ_i ρ( ((z_i − β_R·‖p_AinG − p_RinG,i‖ − γ_R) / σ_eff,i)² ) + ½ Σ_R priors(γ_R, β_R),
/// x = [p_AinG, γ_R, β_R (free where observable)], ρ the optional robust loss (Huber / Cauchy).
/// σ_eff,i (range noise plus reference-position uncertainty) is evaluated at the initial guess.
/// This is the only translation unit of the project's calibrator that includes Ceres.

#include <string>
#include <vector>

#include "calibrator/calibration_problem.h"

namespace meshnav::calib {

struct RefineResult {
  bool converged = false;
  int iterations = 0;
  double final_cost = 0.0;
  std::string message;
  AnchorParams params;
};

class NonlinearRefiner {
 public:
  explicit NonlinearRefiner(const CalibratorOptions& options) : options_(options) {}
  /// Refines `init` on the observations with `use[i]` (empty: all with a slot).
  RefineResult refine(const CalibrationProblem& pb, const AnchorParams& init, const std::vector<bool>& use) const;

 private:
  CalibratorOptions options_;
};

}  // namespace meshnav::calib
