#pragma once
/// @file chi_square.h
/// @brief χ² distribution helpers for consistency tests (NEES, ANEES bounds).
///
/// For a consistent estimator the NEES ε_k = x̃_kᵀ P_k⁻¹ x̃_k of a d-dimensional error is χ²(d).
/// The ANEES over N samples, ε̄ = (1/N) Σ ε_k, satisfies N·ε̄ ~ χ²(N·d) when the samples are
/// independent, so its two-sided (1−α) acceptance interval is
///   [ χ²⁻¹_{N d}(α/2) / N ,  χ²⁻¹_{N d}(1 − α/2) / N ]   (Bar-Shalom, Li, Kirubarajan, §5.4).
/// Consecutive filter errors are strongly correlated, so for long runs the interval is narrow and
/// mostly tells whether ε̄ ≈ d; it is reported as the convention the paper's toolbox uses.

#include "common/chi_square.h"  // chi2Cdf, chi2Quantile (one implementation, Boost.Math)

namespace meshnav::eval {

/// Two-sided acceptance interval of the ANEES of `n_samples` samples of dimension `dof` at
/// confidence `confidence` (0.95 → 2.5 % and 97.5 % quantiles of χ²(n·dof), divided by n).
struct ChiSquareBounds {
  double lower = 0.0;
  double upper = 0.0;
  bool contains(double v) const { return v >= lower && v <= upper; }
};
ChiSquareBounds aneesBounds(int n_samples, int dof, double confidence = 0.95);

}  // namespace meshnav::eval
