#include "estimator/health/anchor_plane_mirror.h"

#include "common/principal_axes.h"

#include <cmath>

namespace meshnav::estimator {

std::optional<AnchorPlaneMirror> AnchorPlaneMirror::of(const std::map<SensorId, Eigen::Vector3d>& anchors,
                                                       const FlightVolume& volume) {
  if (anchors.size() < 3) return std::nullopt;
  std::vector<Eigen::Vector3d> points;
  for (const auto& [id, p] : anchors) points.push_back(p);
  const PrincipalAxes pa = principalAxes(points);
  // Anchors on one line span no plane (the normal is then arbitrary, and the ambiguity a circle).
  if (pa.rms_m(2) > kCoplanarRmsM || pa.rms_m(1) < 1e-6) return std::nullopt;
  const Eigen::Vector3d& c = pa.centroid;
  const Eigen::Vector3d n = pa.axes.col(2);
  // The volume's far side from the plane: every corner must be on the centre's side (or nearly).
  const double centre_side = n.dot(0.5 * (volume.min_m + volume.max_m) - c) >= 0.0 ? 1.0 : -1.0;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d corner((k & 1) ? volume.max_m.x() : volume.min_m.x(), (k & 2) ? volume.max_m.y() : volume.min_m.y(),
                                 (k & 4) ? volume.max_m.z() : volume.min_m.z());
    if (centre_side * n.dot(corner - c) < -kBoundaryToleranceM) return std::nullopt;
  }
  return AnchorPlaneMirror(c, n, centre_side, volume);
}

std::optional<SideConstraint> AnchorPlaneMirror::sideConstraint(double mu_m, double var_m2) {
  if (!(var_m2 > 0.0) || !std::isfinite(mu_m)) return std::nullopt;
  const double sigma = std::sqrt(var_m2), a = mu_m / sigma;
  if (a > kInactiveSigmas || a < -kInactiveSigmas) return std::nullopt;
  const double phi = std::exp(-0.5 * a * a) / std::sqrt(2.0 * M_PI);
  const double Phi = 0.5 * std::erfc(-a / std::sqrt(2.0));
  const double lambda = phi / Phi;
  const double var_t = var_m2 * std::max(1e-9, 1.0 - a * lambda - lambda * lambda);
  if (!(var_t < var_m2)) return std::nullopt;
  const double R = var_m2 * var_t / (var_m2 - var_t);
  return SideConstraint{mu_m + sigma * lambda * (var_m2 + R) / var_m2, R};
}

}  // namespace meshnav::estimator
