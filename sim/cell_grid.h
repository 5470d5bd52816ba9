#pragma once
/// @file cell_grid.h
/// @brief The TDMA cells of a large hall (docs/scenarios.md, "A hundred anchors in TDMA cells"):
/// the hall's floor plan divided into n_x × n_y equal rectangles, each a cell of the UWB network.
///
/// Cell (i, j) covers x ∈ [x_min + i·w_x, x_min + (i+1)·w_x), y likewise, every height; its flat
/// index is c = j·n_x + i. Two cells are **neighbours** when their Chebyshev distance
/// max(|Δi|, |Δj|) ≤ 1 (a cell is its own neighbour): a device ranges to the devices of its cell's
/// 3 × 3 neighbourhood. **Colour** (slot reuse): c ↦ (i mod r_x) + r_x·(j mod r_y) with r_x =
/// min(r, n_x), r_y = min(r, n_y), reuse distance r (3): two different cells of one colour are at
/// least r cells apart along x or y, so for r = 3 their neighbourhoods share no cell and they can
/// use the same slots.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "sim/hall.h"

namespace meshnav::sim {

class CellGrid {
 public:
  /// Throws std::invalid_argument for n_x or n_y < 1 or reuse < 1.
  CellGrid(const Hall& hall, int n_x, int n_y, int reuse = 3);

  int cellsX() const { return n_x_; }
  int cellsY() const { return n_y_; }
  int cellCount() const { return n_x_ * n_y_; }
  /// Cell width along x and y [m].
  Eigen::Vector2d cellSize_m() const;
  int indexX(int cell) const { return cell % n_x_; }
  int indexY(int cell) const { return cell / n_x_; }
  int cellAt(int i, int j) const { return j * n_x_ + i; }
  /// The cell whose floor rectangle holds p (points outside the hall go to the nearest cell).
  int cellOf(const Eigen::Vector3d& p_inG) const;
  /// Chebyshev distance ≤ 1.
  bool neighbours(int a, int b) const;
  /// The cell's 3 × 3 neighbourhood (itself included), ascending.
  std::vector<int> neighbourhood(int cell) const;
  int colour(int cell) const;
  int colourCount() const { return reuse_x_ * reuse_y_; }
  /// The cells of one colour, ascending.
  std::vector<int> cellsOfColour(int colour) const;
  const Hall& hall() const { return hall_; }
  std::string toString() const;

 private:
  Hall hall_;
  int n_x_, n_y_;
  int reuse_x_, reuse_y_;
};

}  // namespace meshnav::sim
