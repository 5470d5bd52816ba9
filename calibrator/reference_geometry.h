#pragma once
/// @file reference_geometry.h
/// @brief Refusal checks before a calibration: enough ranges, enough distinct positions of the
/// moving references, and a 3D spread of them (collinear or coplanar references leave the anchor
/// position ambiguous — a mirror image across the plane fits equally well).

#include <optional>
#include <string>

#include "calibrator/calibration_problem.h"

namespace meshnav::calib {

/// The plane of coplanar moving references, when stationary references off it may tell the
/// anchor's side (`CalibratorOptions::mirror_reference_min_offset_m`).
struct MirrorPlane {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  ///< a point of the plane (the references' centroid) [m]
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit normal
  double reference_offset_m = 0.0;  ///< largest distance of a stationary reference from the plane [m]
  /// p mirrored across the plane: p − 2 ((p − c)·n) n.
  Eigen::Vector3d reflect(const Eigen::Vector3d& p) const { return p - 2.0 * (p - point_m).dot(normal) * normal; }
};

struct GeometryReport {
  CalibrationStatus status = CalibrationStatus::Ok;
  std::string reason;
  int n_used = 0;                 ///< ranges with a usable reference
  int distinct_positions = 0;     ///< distinct moving-reference positions on the grid
  Eigen::Vector3d rms_spread_m = Eigen::Vector3d::Zero();  ///< RMS along principal axes, descending
  /// Set when the moving references are coplanar but stationary references lie off their plane:
  /// the status is Ok and the calibration must fit both sides of this plane.
  std::optional<MirrorPlane> mirror;
};

GeometryReport checkReferenceGeometry(const CalibrationProblem& pb, const CalibratorOptions& options);

}  // namespace meshnav::calib
