#pragma once
/// @file ransac_solver.h
/// @brief Robust calibration (paper §III-C-3): RANSAC around the optimal double method.
///
/// Each iteration draws (deterministically, from a seeded std::mt19937_64) 2·⌈(3 + g + margin)/g⌉
/// ranges of each of the g moving references, solves the linear step on them and scores the
/// hypothesis by its inlier support: range i is an inlier when |z_i − β d̂_i − γ̂_R| < k·(σ_d + σ_p,i),
/// with γ̂_R the median of z − β d̂ over reference R (so a noisy γ of the minimal solve does not
/// cost support) and σ_p,i = √(tr Σ_R,i / 3). Ties go to the smaller truncated squared residual sum.
/// The iteration count adapts to the best inlier ratio w: N = log(1 − P)/log(1 − w^m), clamped to
/// [min, max]. The final linear solution is fitted on the inliers of the best hypothesis.

#include <cstdint>
#include <string>
#include <vector>

#include "calibrator/optimal_double_solver.h"

namespace meshnav::calib {

struct RansacResult {
  bool ok = false;
  std::string reason;
  std::vector<bool> inliers;  ///< per observation of the problem
  int n_inliers = 0;
  int iterations = 0;
  LinearSolution solution;    ///< linear fit on the inliers
};

class RansacSolver {
 public:
  explicit RansacSolver(const CalibratorOptions& options) : options_(options), linear_(options) {}
  /// Same `seed` and problem → same result.
  RansacResult run(const CalibrationProblem& pb, uint64_t seed) const;
  /// Inlier test of one hypothesis (γ re-estimated per reference by the median); returns the count.
  int classify(const CalibrationProblem& pb, const AnchorParams& hypothesis, std::vector<bool>& inliers,
               double* truncated_cost = nullptr) const;

 private:
  CalibratorOptions options_;
  OptimalDoubleSolver linear_;
};

}  // namespace meshnav::calib
