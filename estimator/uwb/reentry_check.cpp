/// @file reentry_check.cpp
/// @brief ReentryCheck: leave-one-out test of the ranges held after an aiding gap (math in the header).

#include "estimator/uwb/reentry_check.h"

#include <Eigen/Cholesky>

#include <set>

namespace meshnav::estimator {

ReentryCheck::Result ReentryCheck::decide(const std::vector<Held>& held, const Eigen::Matrix3d& P_pp, double gate_chi2,
                                          int min_ranges, int min_anchors) {
  Result res;
  res.accepted.assign(held.size(), true);
  const auto enough = [&] {
    std::set<SensorId> anchors;
    int n = 0;
    for (size_t i = 0; i < held.size(); ++i)
      if (res.accepted[i]) ++n, anchors.insert(held[i].anchor);
    return n >= min_ranges && static_cast<int>(anchors.size()) >= min_anchors;
  };
  if (!enough()) return res;
  res.checked = true;
  const Eigen::Matrix3d info_prior = P_pp.inverse();
  while (enough()) {
    int worst = -1;
    double worst_d = gate_chi2;
    for (size_t i = 0; i < held.size(); ++i) {
      if (!res.accepted[i]) continue;
      Eigen::Matrix3d A = info_prior;
      Eigen::Vector3d b = Eigen::Vector3d::Zero();
      for (size_t j = 0; j < held.size(); ++j) {
        if (j == i || !res.accepted[j]) continue;
        A += held[j].u * held[j].u.transpose() / held[j].R_m2;
        b += held[j].u * held[j].nu_m / held[j].R_m2;
      }
      const Eigen::LDLT<Eigen::Matrix3d> ldlt(A);
      const Eigen::Vector3d dp = ldlt.solve(b);
      const double S = held[i].u.dot(ldlt.solve(held[i].u)) + held[i].R_m2;
      const double e = held[i].nu_m - held[i].u.dot(dp);
      const double d = e * e / S;
      if (d > worst_d) worst_d = d, worst = static_cast<int>(i);
    }
    if (worst < 0) break;
    res.accepted[static_cast<size_t>(worst)] = false;
    ++res.rejected;
  }
  return res;
}

}  // namespace meshnav::estimator
