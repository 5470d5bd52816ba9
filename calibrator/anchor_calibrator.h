#pragma once
/// @file anchor_calibrator.h
/// @brief Calibrates one unknown anchor from its ranges to reference devices (paper §III-C,
/// docs/calibration.md): refusal checks → RANSAC (or all ranges) + optimal double linear step →
/// Levenberg–Marquardt refinement (robust loss optional) → re-classification of outliers →
/// consistent covariance Σ = s²·(JᵀWJ + H_prior)⁻¹ with W⁻¹ = σ_d² + β²uᵀΣ_R u and s² = max(1, χ²/dof).

#include <map>
#include <vector>

#include "calibrator/calibration_types.h"
#include "calibrator/calibrator_options.h"

namespace meshnav::calib {

class AnchorCalibrator {
 public:
  explicit AnchorCalibrator(const CalibratorOptions& options) : options_(options) {}

  /// `observations`: ranges between `anchor_id` and its references (any order).
  /// `priors`: a-priori pair biases that override the default priors. `t`: stamp of the result.
  CalibrationResult calibrate(SensorId anchor_id, const std::vector<CalibObservation>& observations,
                              const std::map<SensorId, ReferencePrior>& priors = {}, Timestamp t = {}) const;

  const CalibratorOptions& options() const { return options_; }

 private:
  CalibratorOptions options_;
};

}  // namespace meshnav::calib
