#pragma once
/// @file anchor_belief_intersection.h
/// @brief One belief of an anchor from several vehicles' beliefs of it, by covariance
/// intersection (docs/decisions/016-fleet-sharing.md, "Shared anchors").
///
/// Every vehicle's belief of a calibrated anchor starts from the same ANCHOR_INIT and is refined
/// by its own ranges: the beliefs are correlated by an unknown amount, so neither their product
/// (which counts the common calibration once per vehicle) nor the tightest alone is right. CI
/// bounds any correlation: for beliefs (x₁, P₁), (x₂, P₂) and ω ∈ [0, 1]
///   P⁻¹ = ω P₁⁻¹ + (1 − ω) P₂⁻¹,   x = P (ω P₁⁻¹ x₁ + (1 − ω) P₂⁻¹ x₂),
/// consistent (P ⪰ the true error covariance) whatever the cross-covariance of the two errors,
/// with ω chosen to minimise tr P (golden-section search on [0, 1]). More than two: folded in
/// order, each step a CI of the running result and the next belief (each step consistent, so
/// the result is).

#include <vector>

#include <Eigen/Dense>

#include "common/types.h"

namespace meshnav::pipeline {

struct GaussianBelief3 {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();
};

class AnchorBeliefIntersection {
 public:
  /// The CI of two beliefs with the trace-minimising ω (`omega`, if not null: the weight of `a`).
  /// Covariances must be symmetric positive definite.
  static GaussianBelief3 fuse(const GaussianBelief3& a, const GaussianBelief3& b, double* omega = nullptr);
  /// The CI of every belief, folded in order; a belief with zero covariance (an exactly known
  /// anchor) is returned as it is. Throws std::invalid_argument for an empty list.
  static GaussianBelief3 fuseAll(const std::vector<GaussianBelief3>& beliefs);
  /// Per anchor id in any of the vehicles' lists, fuseAll of its beliefs in vehicle order, stamped
  /// with the newest of their times; in id order.
  static std::vector<AnchorEstimate> fuseVehicles(const std::vector<std::vector<AnchorEstimate>>& per_vehicle);
};

}  // namespace meshnav::pipeline
