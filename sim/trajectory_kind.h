#pragma once
/// @file trajectory_kind.h
/// @brief The kinds of simulated motion (`--trajectory`).

#include <optional>
#include <string>
#include <string_view>

namespace meshnav::sim {

enum class TrajectoryKind { Spiral, Figure8, Lawnmower, Helix, Hover, Walk };

/// "spiral", "figure8", "lawnmower", "helix", "hover", "walk".
std::string toString(TrajectoryKind kind);
/// Inverse of `toString`; nullopt for an unknown name.
std::optional<TrajectoryKind> parseTrajectoryKind(std::string_view name);
/// "spiral|figure8|lawnmower|helix|hover|walk".
std::string trajectoryKindNames();

}  // namespace meshnav::sim
