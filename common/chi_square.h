#pragma once
/// @file chi_square.h
/// @brief The χ² distribution, one implementation for the whole project (Boost.Math): gates of
/// the estimator (NIS ≤ χ²⁻¹_d(p)), NEES/ANEES bounds of the evaluation.

namespace meshnav {

/// χ²(dof) cumulative distribution function at x ≥ 0 (dof > 0, need not be an integer).
/// Throws std::invalid_argument for dof ≤ 0 or a negative or non-finite x.
double chi2Cdf(double x, double dof);

/// Quantile: the x with P(χ²_dof ≤ x) = p, for 0 < p < 1 and dof > 0.
/// Throws std::invalid_argument otherwise.
double chi2Quantile(double dof, double p);

}  // namespace meshnav
