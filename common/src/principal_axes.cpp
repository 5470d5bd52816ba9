#include "common/principal_axes.h"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace meshnav {

PrincipalAxes principalAxes(const std::vector<Eigen::Vector3d>& points) {
  PrincipalAxes a;
  if (points.empty()) return a;
  for (const auto& p : points) a.centroid += p;
  a.centroid /= static_cast<double>(points.size());
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  for (const auto& p : points) C += (p - a.centroid) * (p - a.centroid).transpose();
  C /= static_cast<double>(points.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(C);
  const Eigen::Vector3d ev = es.eigenvalues().cwiseMax(0.0);  // ascending
  for (int k = 0; k < 3; ++k) {
    a.rms_m(k) = std::sqrt(ev(2 - k));
    a.axes.col(k) = es.eigenvectors().col(2 - k);
  }
  return a;
}

}  // namespace meshnav
