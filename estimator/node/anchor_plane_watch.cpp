#include "estimator/node/anchor_plane_watch.h"

#include <Eigen/SVD>
#include <cmath>

namespace meshnav::estimator {

std::optional<AnchorPlaneWatch> AnchorPlaneWatch::of(const std::map<SensorId, Eigen::Vector3d>& anchors) {
  if (anchors.size() < 3) return std::nullopt;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& [id, p] : anchors) c += p;
  c /= static_cast<double>(anchors.size());
  Eigen::MatrixXd X(anchors.size(), 3);
  int i = 0;
  for (const auto& [id, p] : anchors) X.row(i++) = (p - c).transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(X, Eigen::ComputeFullV);
  const double rms_off = svd.singularValues()(2) / std::sqrt(static_cast<double>(anchors.size()));
  // Three anchors on one line span no plane (the normal is then arbitrary): not watched.
  if (rms_off > kCoplanarRmsM || svd.singularValues()(1) < 1e-6) return std::nullopt;
  return AnchorPlaneWatch(c, svd.matrixV().col(2));
}

bool AnchorPlaneWatch::crossed(const Eigen::Vector3d& p_IinG) {
  const double d = distance(p_IinG);
  if (std::abs(d) < kHysteresisM) return false;
  const int side = d > 0.0 ? 1 : -1;
  const bool changed = side_ && *side_ != side;
  side_ = side;
  return changed;
}

}  // namespace meshnav::estimator
