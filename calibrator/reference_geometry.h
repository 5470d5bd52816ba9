#pragma once
/// @file reference_geometry.h
/// @brief Refusal checks before a calibration: enough ranges, enough distinct positions of the
/// moving references, and a 3D spread of them (collinear or coplanar references leave the anchor
/// position ambiguous — a mirror image across the plane fits equally well).

#include <string>

#include "calibrator/calibration_problem.h"

namespace meshnav::calib {

struct GeometryReport {
  CalibrationStatus status = CalibrationStatus::Ok;
  std::string reason;
  int n_used = 0;                 ///< ranges with a usable reference
  int distinct_positions = 0;     ///< distinct moving-reference positions on the grid
  Eigen::Vector3d rms_spread_m = Eigen::Vector3d::Zero();  ///< RMS along principal axes, descending
};

GeometryReport checkReferenceGeometry(const CalibrationProblem& pb, const CalibratorOptions& options);

}  // namespace meshnav::calib
