#pragma once
/// @file anchor_plane_mirror.h
/// @brief The mirror image across the plane of coplanar known anchors, told apart by the flight volume.
///
/// Ranges to anchors in one plane (centroid c, unit normal n) are the same for a position p and its
/// mirror image p' = p − 2 n nᵀ(p − c). Near that plane the filter has almost no information along
/// n, and it can slide across it onto the mirror image, where the ranges then hold it (seed-8 run113:
/// a three-tag lawnmower 0.75 m from four anchors on one wall ended 1.7 m behind the wall and
/// reached 4.2 m of error; seed-4 run050 the same with one tag; docs/robustness.md, "The flight volume").
/// When the user states the volume the vehicle stays in (setup.yaml `flight_volume`) and anchors
/// hang on its walls or ceiling, the two images are told apart: an estimate outside the volume
/// whose mirror image is inside is the mirror image. The node then reflects position and velocity
/// (EstimatorNode::checkFlightVolume); attitude and biases are the same for both images.
///
/// The plane: c and n (smallest singular vector) of the known anchors, used only when they lie
/// within `kCoplanarRmsM` RMS of it, span more than a line, and bound the volume: every corner of
/// the volume lies on one side of the plane or at most `kBoundaryToleranceM` beyond it (anchors on
/// a wall, on the ceiling). A plane through the volume (seed-4 run107: three anchors on three walls)
/// is crossed by real flights, and there an estimate just outside the volume is not a mirror image.

#include <map>
#include <optional>

#include <Eigen/Core>

#include "common/setup.h"
#include "common/types.h"

namespace meshnav::estimator {

/// A scalar pseudo-measurement z of the inward distance d with variance R.
struct SideConstraint {
  double z = 0.0;  ///< [m]
  double R = 0.0;  ///< [m²]
};

class AnchorPlaneMirror {
 public:
  static constexpr double kCoplanarRmsM = 0.15;  ///< anchors this close (RMS) to one plane are coplanar [m]
  static constexpr double kBoundaryToleranceM = 0.5;  ///< how far the volume may reach beyond the plane [m]

  /// None when fewer than three anchors, when they are not coplanar or lie on one line, or when
  /// their plane cuts through the volume.
  static std::optional<AnchorPlaneMirror> of(const std::map<SensorId, Eigen::Vector3d>& anchors,
                                             const FlightVolume& volume);

  /// p' = p − 2 n nᵀ(p − c).
  Eigen::Vector3d mirror(const Eigen::Vector3d& p) const { return p - 2.0 * n_ * n_.dot(p - c_); }
  /// The reflection of a direction (velocity): I − 2 n nᵀ.
  Eigen::Matrix3d reflection() const { return Eigen::Matrix3d::Identity() - 2.0 * n_ * n_.transpose(); }
  /// True when p lies more than `margin_m` outside the volume and its mirror image inside it.
  bool isMirrorImage(const Eigen::Vector3d& p, double margin_m) const {
    return volume_.distanceOutside(p) > margin_m && volume_.distanceOutside(mirror(p)) == 0.0;
  }
  const Eigen::Vector3d& normal() const { return n_; }
  /// Simon's PDF truncation of d ~ N(μ, σ²) to d ≥ 0 as the pseudo-measurement whose Kalman update
  /// gives the truncated moments: with a = μ/σ and λ = φ(a)/Φ(a), μ⁺ = μ + σλ and
  /// σ⁺² = σ²(1 − aλ − λ²); then R = σ²σ⁺²/(σ² − σ⁺²) and z = μ + (μ⁺ − μ)(σ² + R)/σ². None when
  /// a > `kInactiveSigmas` (the constraint moves nothing) or a < −kInactiveSigmas (the mirror side:
  /// reflection, not truncation).
  static std::optional<SideConstraint> sideConstraint(double mu_m, double var_m2);
  static constexpr double kInactiveSigmas = 3.0;

  /// Unit normal of the plane pointing into the volume, and the signed distance of p along it.
  Eigen::Vector3d inwardNormal() const { return inward_ * n_; }
  double inwardDistance(const Eigen::Vector3d& p) const { return inward_ * n_.dot(p - c_); }

 private:
  AnchorPlaneMirror(const Eigen::Vector3d& c, const Eigen::Vector3d& n, double inward, const FlightVolume& v)
      : c_(c), n_(n), inward_(inward), volume_(v) {}
  Eigen::Vector3d c_, n_;
  double inward_ = 1.0;  ///< +1 when n points into the volume, else −1
  FlightVolume volume_;
};

}  // namespace meshnav::estimator
