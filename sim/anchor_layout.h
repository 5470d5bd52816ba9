#pragma once
/// @file anchor_layout.h
/// @brief Where the UWB anchors of a simulated hall are (`--anchor-layout`, `--known`, `--unknown`).
///
/// Kinds (hall box [min, max], height H; anchors mounted 0.1 m off a wall, 0.3 m from corners,
/// floor and ceiling unless said otherwise):
///  - paper:    the paper's nine anchors (docs/scenarios.md) mapped affinely from the paper's hall into this
///              one; known = the first N of 101, 102, 103, 104, 106, …, unknown = the next M;
///  - walls:    every anchor on a wall, the walls taken in turn from a seeded first one, random
///              position along the wall and random height;
///  - one-wall: the known anchors all on one wall, spread along it in strata, alternately low
///              (< 0.45 H) and high (> 0.55 H); the unknown ones on the three other walls;
///  - ceiling:  the known anchors 0.15–0.4 m below the ceiling (nearly coplanar), ≥ 0.5 m from the
///              walls; the unknown ones on the walls;
///  - random:   uniform in the volume but within 0.1–1 m of the nearest wall, z ∈ [0.2, H − 0.2].
/// Ids count up from 101, skipping tag ids (the paper layout keeps the paper's ids). All draws
/// come from `RandomStream::deriveSeed(seed, "anchor_layout:<kind>")`.

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>

#include "common/types.h"
#include "sim/hall.h"

namespace meshnav::sim {

enum class AnchorLayoutKind { Paper, Walls, OneWall, Ceiling, Random };

std::string toString(AnchorLayoutKind kind);
/// Inverse of `toString`; nullopt for an unknown name.
std::optional<AnchorLayoutKind> parseAnchorLayoutKind(std::string_view name);
/// "paper|walls|one-wall|ceiling|random".
std::string anchorLayoutKindNames();

struct AnchorLayout {
  std::map<SensorId, Eigen::Vector3d> anchors_p_AinG;  ///< every anchor (truth) [m]
  std::set<SensorId> known_ids;                        ///< those written to setup.yaml

  /// Throws std::invalid_argument for n_known < 1, n_unknown < 0, or more anchors than the
  /// paper layout has (9).
  static AnchorLayout generate(AnchorLayoutKind kind, const Hall& hall, int n_known, int n_unknown,
                               const std::set<SensorId>& tag_ids, uint64_t seed);
};

}  // namespace meshnav::sim
