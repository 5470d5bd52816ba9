#pragma once
/// @file motion_aligner_internals.h
/// @brief The unknowns' indices and types shared by the two translation units of MotionAligner
/// (motion_aligner.cpp: window and observation model; motion_aligner_fit.cpp: the fit). Internal.

#include <Eigen/Core>

namespace meshnav::estimator::motion_aligner_internal {

constexpr int kDim = 16;  ///< [δp₀, δv₀, δθ, δb_a, δb_ω, δb_H]
constexpr int kBh = 15;   ///< index of δb_H
using VecU = Eigen::Matrix<double, kDim, 1>;
using MatU = Eigen::Matrix<double, kDim, kDim>;

}  // namespace meshnav::estimator::motion_aligner_internal
