#pragma once
/// @file anchor_plane_watch.h
/// @brief Watches the side of the known anchors' plane the estimate is on.
///
/// Ranges to anchors that lie in one plane (three known anchors always do; anchors on one wall or
/// on the ceiling nearly do) are the same for a position and its mirror image across that plane,
/// so near the plane the filter has almost no information along its normal n and can slide
/// across it, after which the ranges hold it on the mirror side (seed-4 sweep run050: a one-tag
/// lawnmower under three anchors on one wall crossed at 45.5 s, 1.05 m from the wall, and ran
/// 4.7 m off until a degraded-state re-alignment at 50.8 s). A crossing of the estimate is the one
/// moment that ambiguity bites, so the node checks it there against the in-motion alignment,
/// whose window of IMU and ranges tells a mirror image from a real crossing when the motion does
/// (docs/robustness.md, "Crossing the anchors' plane").
///
/// The plane: centroid c and normal n (smallest singular vector) of the known anchors; used only
/// when they lie within `kCoplanarRmsM` RMS of it. Side s = sign(nᵀ(p − c)), changed only once
/// |nᵀ(p − c)| exceeds `kHysteresisM` on the other side.

#include <map>
#include <optional>

#include <Eigen/Core>

#include "common/types.h"

namespace meshnav::estimator {

class AnchorPlaneWatch {
 public:
  static constexpr double kCoplanarRmsM = 0.15;  ///< anchors this close (RMS) to one plane are coplanar [m]
  static constexpr double kHysteresisM = 0.10;   ///< distance beyond the plane before a side change counts [m]

  /// None when fewer than three anchors or they are not coplanar.
  static std::optional<AnchorPlaneWatch> of(const std::map<SensorId, Eigen::Vector3d>& anchors);

  /// Feeds the estimated position; true when its side of the plane changed since the last call
  /// that had a side (the first position only sets it).
  bool crossed(const Eigen::Vector3d& p_IinG);
  /// Forgets the side (the pose was replaced).
  void reset() { side_.reset(); }

  const Eigen::Vector3d& normal() const { return n_; }
  /// Signed distance nᵀ(p − c) [m].
  double distance(const Eigen::Vector3d& p) const { return n_.dot(p - c_); }

 private:
  AnchorPlaneWatch(const Eigen::Vector3d& c, const Eigen::Vector3d& n) : c_(c), n_(n) {}
  Eigen::Vector3d c_, n_;
  std::optional<int> side_;
};

}  // namespace meshnav::estimator
