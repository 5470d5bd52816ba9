#pragma once
/// @file anchor_init_io.h
/// @brief Calibration results file, docs/formats.md (one entry per anchor: id, t, p_AinG, p_AinG_cov
/// (3×3 row-major), ref_ids, const_biases, dist_biases, sigma_const_biases, sigma_dist_biases,
/// sigma_ranges, n_inliers, n_outliers, and optionally cov_gamma_p (n × 3 row-major: cov(γ_i, p_AinG))
/// with cov_gamma (n × n row-major): the joint covariance of position and γ, issue 10; files
/// without them still read, as anchors whose γ are independent of the position; refused anchors
/// under `refused:`). Written by the
/// calibrator and by the logger (ANCHOR_INIT), read by the estimator's users and the evaluation.

#include <string>
#include <vector>

#include "common/types.h"

namespace meshnav {

/// An anchor the calibrator refused, with the reason.
struct RefusedAnchor {
  SensorId id = 0;
  std::string status;  ///< e.g. "degenerate_geometry"
  std::string reason;  ///< human-readable
};

/// What is wrong with the values of `a` (empty: nothing): an id ≤ 0, a position or covariance not
/// finite, cov_p_m2 not positive definite, a pair bias with β ≤ 0, σ_γ < 0 or a value not finite,
/// joint covariance sizes that do not fit the biases, or a joint covariance of the position and
/// the γ with σ_γ > 0 (the candidates for states) that is not positive definite. The one check
/// of an ANCHOR_INIT and of ESTIMATOR_CMD's anchor, wherever they come from.
std::string anchorInitValueError(const AnchorInit& a);

/// Writes `inits` (PairBias a = reference device, b = the anchor) and `refused`. Throws
/// std::runtime_error naming the file on I/O failure.
void writeAnchorInitsYaml(const std::vector<AnchorInit>& inits, const std::string& path,
                          const std::vector<RefusedAnchor>& refused = {});

/// Reads the `anchors:` entries (or a top-level list) back. Throws std::runtime_error naming the
/// file and the key on a malformed file.
std::vector<AnchorInit> readAnchorInitsYaml(const std::string& path);

}  // namespace meshnav
