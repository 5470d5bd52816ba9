/// @file cell_grid.cpp
/// @brief CellGrid: cells, neighbourhoods and slot-reuse colours of a large hall.

#include "sim/cell_grid.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace meshnav::sim {

CellGrid::CellGrid(const Hall& hall, int n_x, int n_y, int reuse)
    : hall_(hall), n_x_(n_x), n_y_(n_y), reuse_x_(std::min(reuse, n_x)), reuse_y_(std::min(reuse, n_y)) {
  if (n_x < 1 || n_y < 1) throw std::invalid_argument("CellGrid: needs at least one cell along x and y");
  if (reuse < 1) throw std::invalid_argument("CellGrid: the reuse distance must be >= 1");
}

Eigen::Vector2d CellGrid::cellSize_m() const {
  const Eigen::Vector3d size = hall_.size();
  return {size.x() / n_x_, size.y() / n_y_};
}

int CellGrid::cellOf(const Eigen::Vector3d& p_inG) const {
  const Eigen::Vector2d w = cellSize_m();
  const int i = std::clamp(static_cast<int>(std::floor((p_inG.x() - hall_.min_m.x()) / w.x())), 0, n_x_ - 1);
  const int j = std::clamp(static_cast<int>(std::floor((p_inG.y() - hall_.min_m.y()) / w.y())), 0, n_y_ - 1);
  return cellAt(i, j);
}

bool CellGrid::neighbours(int a, int b) const {
  return std::abs(indexX(a) - indexX(b)) <= 1 && std::abs(indexY(a) - indexY(b)) <= 1;
}

std::vector<int> CellGrid::neighbourhood(int cell) const {
  std::vector<int> out;
  const int i = indexX(cell), j = indexY(cell);
  for (int jj = std::max(0, j - 1); jj <= std::min(n_y_ - 1, j + 1); ++jj)
    for (int ii = std::max(0, i - 1); ii <= std::min(n_x_ - 1, i + 1); ++ii) out.push_back(cellAt(ii, jj));
  return out;
}

int CellGrid::colour(int cell) const { return indexX(cell) % reuse_x_ + reuse_x_ * (indexY(cell) % reuse_y_); }

std::vector<int> CellGrid::cellsOfColour(int colour_index) const {
  std::vector<int> out;
  for (int c = 0; c < cellCount(); ++c)
    if (colour(c) == colour_index) out.push_back(c);
  return out;
}

std::string CellGrid::toString() const {
  std::ostringstream s;
  const Eigen::Vector2d w = cellSize_m();
  s << n_x_ << " x " << n_y_ << " TDMA cells of " << w.x() << " x " << w.y() << " m, " << colourCount()
    << " slot-reuse colours";
  return s.str();
}

}  // namespace meshnav::sim
