#pragma once
/// @file trajectory_alignment.h
/// @brief Alignment of an estimated trajectory to ground truth that lives in another frame, before
/// the absolute trajectory error (ATE) is computed — the convention of evo and
/// rpg_trajectory_evaluation.
///
/// Given associated positions p_k (estimate, frame E) and g_k (truth, frame T), k = 1..N, find the
/// rigid transform (R, t) minimising Σ_k ‖g_k − (R p_k + t)‖² (Umeyama 1991, without scale):
///   μ_p = (1/N) Σ p_k,  μ_g = (1/N) Σ g_k,  Σ_gp = (1/N) Σ (g_k − μ_g)(p_k − μ_p)ᵀ = U D Vᵀ (SVD),
///   S = diag(1, 1, det(U) det(V)),  R = U S Vᵀ,  t = μ_g − R μ_p.
/// Yaw-only (gravity-aligned frames): R = R_z(ψ) with, on the centred points p' = p − μ_p and
/// g' = g − μ_g, ψ = atan2(Σ (p'_x g'_y − p'_y g'_x), Σ (p'_x g'_x + p'_y g'_y)), t = μ_g − R μ_p.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "common/types.h"

namespace meshnav::eval {

/// How the estimate is brought into the truth's frame before the errors are taken.
enum class AlignmentMode {
  None,  ///< estimate and truth share the frame
  Se3,   ///< rotation + translation (Umeyama without scale)
  Yaw,   ///< rotation about z + translation (both frames gravity aligned)
};

/// "none" | "se3" | "yaw"; nullopt otherwise.
std::optional<AlignmentMode> parseAlignmentMode(const std::string& text);
std::string toString(AlignmentMode mode);

/// p_T = R_EtoT p_E + t_EinT: maps points of the estimate frame E into the truth frame T.
struct RigidTransform {
  Eigen::Matrix3d R_EtoT = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t_EinT_m = Eigen::Vector3d::Zero();  ///< origin of E in T [m]

  Eigen::Vector3d apply(const Eigen::Vector3d& p_E) const { return R_EtoT * p_E + t_EinT_m; }
  /// The pose, velocity and covariances of `est` expressed in T (orientation covariance is in the
  /// body frame and stays as it is).
  PoseEstimate apply(const PoseEstimate& est) const;
};

/// Least-squares (R, t) of `mode` from associated positions (same length). None gives identity;
/// nullopt when there are too few pairs (se3: 3, yaw: 2) or the points are degenerate (all equal).
std::optional<RigidTransform> alignPositions(const std::vector<Eigen::Vector3d>& p_est_E,
                                             const std::vector<Eigen::Vector3d>& p_true_T, AlignmentMode mode);

}  // namespace meshnav::eval
