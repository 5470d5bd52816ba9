#pragma once
/// @file calibration_io.h
/// @brief Calibration results as YAML (docs/formats.md), one entry per anchor:
/// @code
/// anchors:
///   - id: 106
///     t: 80.000000                 # [s]
///     p_AinG: [x, y, z]            # [m]
///     p_AinG_cov: [9 values]       # 3×3 row-major [m²]
///     ref_ids: [100, 101, ...]
///     const_biases: [...]          # γ per reference [m]
///     dist_biases: [...]           # β per reference [-]
///     sigma_const_biases: [...]    # [m]
///     sigma_dist_biases: [...]     # [-] (0: β fixed, not estimated)
///     sigma_ranges: [...]          # residual σ of each pair [m] (extension)
///     n_inliers: 700
///     n_outliers: 15
/// refused:
///   - {id: 109, status: too_few_measurements, reason: "..."}
/// @endcode

#include <string>
#include <vector>

#include "calibrator/calibration_types.h"

namespace meshnav::calib {

/// Writes every result in the format of common/anchor_init_io.h (refused ones under `refused:`).
/// Throws std::runtime_error on I/O failure.
void writeCalibrationYaml(const std::vector<CalibrationResult>& results, const std::string& path);

/// Reading the file back: `meshnav::readAnchorInitsYaml` (common/anchor_init_io.h).

}  // namespace meshnav::calib
