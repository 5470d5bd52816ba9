#pragma once
/// @file grid_anchor_layout.h
/// @brief A hundred anchors (or any number ≥ 4) on a regular grid over a large hall, in TDMA cells
/// (`meshnav_sim --vehicles N --anchors M`, docs/scenarios.md "A hundred anchors in TDMA cells").
///
/// Grid: g_x = max(2, round(√(M·X/Y))) columns, g_y = ⌈M/g_x⌉ rows (at least 2), spacing s_x = X/g_x,
/// s_y = Y/g_y; point (i, j) nominally at x = x_min + (i + ½)s_x, y = y_min + (j + ½)s_y, filled row
/// by row (j outer) up to M points (40 × 40 m, M = 100: 10 × 10 points 4 m apart).
/// Mounts and heights (hall height H): points on the grid's outer ring are moved onto the nearest
/// wall(s), 0.1 m inside (mount `wall`); the level (i mod 2) + 2 (j mod 2) gives the height
/// z ∈ {1.0 m, 0.35 H, 0.65 H, H − 0.3 m} (each 2 × 2 block of points has all four); inner points at
/// H − 0.3 m hang from the **ceiling**, the other inner points are on a **pillar** (a thin pole at
/// the grid point; the simulator does not model what it hides).
/// Cells: ⌈g_x/2⌉ × ⌈g_y/2⌉ (`CellGrid`, 8 × 8 m for 100 anchors in 40 × 40 m); an anchor belongs to
/// the cell of its nominal grid point, so each cell holds up to 2 × 2 anchors.
/// Fly-by anchors: `n_unknown` of them, drawn without replacement from
/// `RandomStream::deriveSeed(seed, "anchor_grid:unknown")`; the others are known (setup.yaml).
/// Ids count up from 101, skipping `reserved_ids` (the fleet's tag ids).

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "common/types.h"
#include "sim/cell_grid.h"
#include "sim/hall.h"

namespace meshnav::sim {

enum class AnchorMount { Wall, Pillar, Ceiling };
std::string toString(AnchorMount mount);

struct GridAnchor {
  SensorId id = 0;
  Eigen::Vector3d p_AinG = Eigen::Vector3d::Zero();  ///< [m]
  int grid_x = 0, grid_y = 0;                        ///< grid point (i, j)
  int cell = 0;                                      ///< flat CellGrid index
  AnchorMount mount = AnchorMount::Pillar;
  bool known = true;                                 ///< written to setup.yaml
};

class GridAnchorLayout {
 public:
  /// Throws std::invalid_argument for n_anchors < 4, n_unknown outside [0, n_anchors − 3].
  GridAnchorLayout(const Hall& hall, int n_anchors, int n_unknown, const std::set<SensorId>& reserved_ids,
                   uint64_t seed);

  const std::vector<GridAnchor>& anchors() const { return anchors_; }
  const CellGrid& cells() const { return cells_; }
  int pointsX() const { return g_x_; }
  int pointsY() const { return g_y_; }
  /// Anchor ids of one cell, ascending.
  const std::vector<SensorId>& anchorsOfCell(int cell) const { return by_cell_.at(static_cast<size_t>(cell)); }
  /// The anchors of a cell's 3 × 3 neighbourhood, ascending (what a device in the cell ranges to).
  std::vector<SensorId> anchorsNear(int cell) const;
  /// The cell of an anchor; throws std::out_of_range for an unknown id.
  int cellOfAnchor(SensorId id) const;
  std::map<SensorId, Eigen::Vector3d> positions() const;
  std::set<SensorId> knownIds() const;
  /// Largest number of anchors in one cell.
  int maxAnchorsPerCell() const;
  std::string toString() const;

 private:
  int g_x_ = 0, g_y_ = 0;
  CellGrid cells_;
  std::vector<GridAnchor> anchors_;
  std::vector<std::vector<SensorId>> by_cell_;
  std::map<SensorId, size_t> index_;
};

}  // namespace meshnav::sim
