/// @file anchor_belief_intersection.cpp
/// @brief AnchorBeliefIntersection: covariance intersection of 3-D beliefs.

#include "pipeline/anchor_belief_intersection.h"

#include <cmath>
#include <map>
#include <stdexcept>

namespace meshnav::pipeline {

namespace {

/// P(ω) = (ω A⁻¹ + (1 − ω) B⁻¹)⁻¹.
Eigen::Matrix3d ciCovariance(const Eigen::Matrix3d& Ai, const Eigen::Matrix3d& Bi, double w) {
  return (w * Ai + (1.0 - w) * Bi).inverse();
}

}  // namespace

GaussianBelief3 AnchorBeliefIntersection::fuse(const GaussianBelief3& a, const GaussianBelief3& b, double* omega) {
  const Eigen::Matrix3d Ai = a.cov.inverse(), Bi = b.cov.inverse();
  // tr P(ω) is convex in ω (the trace of a matrix-convex function of an affine argument): golden section.
  const double g = (std::sqrt(5.0) - 1.0) / 2.0;
  double lo = 0.0, hi = 1.0;
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
  double f1 = ciCovariance(Ai, Bi, x1).trace(), f2 = ciCovariance(Ai, Bi, x2).trace();
  for (int it = 0; it < 60 && hi - lo > 1e-12; ++it) {
    if (f1 <= f2) {
      hi = x2;
      x2 = x1;
      f2 = f1;
      x1 = hi - g * (hi - lo);
      f1 = ciCovariance(Ai, Bi, x1).trace();
    } else {
      lo = x1;
      x1 = x2;
      f1 = f2;
      x2 = lo + g * (hi - lo);
      f2 = ciCovariance(Ai, Bi, x2).trace();
    }
  }
  double w = 0.5 * (lo + hi);
  // The ends exactly when they are the best (to rounding: one belief at least as tight as any mix).
  constexpr double kRel = 1e-9;
  if (a.cov.trace() <= ciCovariance(Ai, Bi, w).trace() * (1.0 + kRel)) w = 1.0;
  else if (b.cov.trace() <= ciCovariance(Ai, Bi, w).trace() * (1.0 + kRel)) w = 0.0;
  GaussianBelief3 out;
  out.cov = w == 1.0 ? a.cov : w == 0.0 ? b.cov : ciCovariance(Ai, Bi, w);
  out.cov = 0.5 * (out.cov + out.cov.transpose());
  out.mean = w == 1.0 ? a.mean : w == 0.0 ? b.mean : Eigen::Vector3d(out.cov * (w * Ai * a.mean + (1.0 - w) * Bi * b.mean));
  if (omega) *omega = w;
  return out;
}

GaussianBelief3 AnchorBeliefIntersection::fuseAll(const std::vector<GaussianBelief3>& beliefs) {
  if (beliefs.empty()) throw std::invalid_argument("AnchorBeliefIntersection::fuseAll: no belief");
  // An exactly known anchor (zero covariance) is what it is.
  for (const GaussianBelief3& b : beliefs)
    if (b.cov.isZero(0.0)) return b;
  GaussianBelief3 out = beliefs.front();
  for (size_t k = 1; k < beliefs.size(); ++k) out = fuse(out, beliefs[k]);
  return out;
}

std::vector<AnchorEstimate> AnchorBeliefIntersection::fuseVehicles(
    const std::vector<std::vector<AnchorEstimate>>& per_vehicle) {
  std::map<SensorId, std::vector<GaussianBelief3>> beliefs_of;
  std::map<SensorId, Timestamp> newest;
  for (const auto& list : per_vehicle)
    for (const AnchorEstimate& a : list) {
      beliefs_of[a.id].push_back({a.p_AinG, a.cov_p_m2});
      auto [it, fresh] = newest.emplace(a.id, a.t);
      if (!fresh && it->second < a.t) it->second = a.t;
    }
  std::vector<AnchorEstimate> out;
  for (const auto& [id, list] : beliefs_of) {
    const GaussianBelief3 f = fuseAll(list);
    AnchorEstimate a;
    a.t = newest.at(id);
    a.id = id;
    a.p_AinG = f.mean;
    a.cov_p_m2 = f.cov;
    out.push_back(a);
  }
  return out;
}

}  // namespace meshnav::pipeline
