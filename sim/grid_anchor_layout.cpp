/// @file grid_anchor_layout.cpp
/// @brief GridAnchorLayout: anchors on walls, pillars and the ceiling of a large hall, in cells.

#include "sim/grid_anchor_layout.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "sim/random_stream.h"

namespace meshnav::sim {

namespace {

constexpr double kWallInset_m = 0.1;  ///< a wall anchor hangs this far inside the wall
constexpr double kCeilingGap_m = 0.3;  ///< a ceiling anchor hangs this far below the ceiling
constexpr double kLowHeight_m = 1.0;   ///< the lowest level

int columnsFor(int n, const Hall& hall) {
  const Eigen::Vector3d size = hall.size();
  return std::max(2, static_cast<int>(std::lround(std::sqrt(n * size.x() / size.y()))));
}

int rowsFor(int n, int columns) { return std::max(2, (n + columns - 1) / columns); }

}  // namespace

std::string toString(AnchorMount mount) {
  switch (mount) {
    case AnchorMount::Wall: return "wall";
    case AnchorMount::Pillar: return "pillar";
    case AnchorMount::Ceiling: return "ceiling";
  }
  return "?";
}

GridAnchorLayout::GridAnchorLayout(const Hall& hall, int n_anchors, int n_unknown,
                                   const std::set<SensorId>& reserved_ids, uint64_t seed)
    : g_x_(columnsFor(std::max(n_anchors, 1), hall)),
      g_y_(rowsFor(std::max(n_anchors, 1), g_x_)),
      cells_(hall, (g_x_ + 1) / 2, (g_y_ + 1) / 2) {
  if (n_anchors < 4) throw std::invalid_argument("GridAnchorLayout: needs at least 4 anchors");
  if (n_unknown < 0 || n_unknown > n_anchors - 3)
    throw std::invalid_argument("GridAnchorLayout: the fly-by anchors must number 0 to anchors - 3");
  const Eigen::Vector3d size = hall.size();
  const double s_x = size.x() / g_x_, s_y = size.y() / g_y_, H = size.z();
  const double levels[4] = {kLowHeight_m, 0.35 * H, 0.65 * H, H - kCeilingGap_m};
  SensorId next_id = 101;
  by_cell_.assign(static_cast<size_t>(cells_.cellCount()), {});
  for (int n = 0; n < n_anchors; ++n) {
    GridAnchor a;
    a.grid_x = n % g_x_;
    a.grid_y = n / g_x_;
    while (reserved_ids.count(next_id)) ++next_id;
    a.id = next_id++;
    const Eigen::Vector3d nominal(hall.min_m.x() + (a.grid_x + 0.5) * s_x, hall.min_m.y() + (a.grid_y + 0.5) * s_y,
                                  hall.min_m.z());
    a.cell = cells_.cellOf(nominal);
    const int level = a.grid_x % 2 + 2 * (a.grid_y % 2);
    a.p_AinG = nominal;
    a.p_AinG.z() = hall.min_m.z() + std::clamp(levels[level], 0.3, H - kCeilingGap_m);
    const bool west = a.grid_x == 0, east = a.grid_x == g_x_ - 1, south = a.grid_y == 0, north = a.grid_y == g_y_ - 1;
    if (west) a.p_AinG.x() = hall.min_m.x() + kWallInset_m;
    if (east) a.p_AinG.x() = hall.max_m.x() - kWallInset_m;
    if (south) a.p_AinG.y() = hall.min_m.y() + kWallInset_m;
    if (north) a.p_AinG.y() = hall.max_m.y() - kWallInset_m;
    a.mount = (west || east || south || north) ? AnchorMount::Wall
              : level == 3                     ? AnchorMount::Ceiling
                                               : AnchorMount::Pillar;
    index_[a.id] = anchors_.size();
    by_cell_[static_cast<size_t>(a.cell)].push_back(a.id);
    anchors_.push_back(a);
  }
  // The fly-by anchors: a seeded draw without replacement (partial Fisher–Yates).
  std::vector<size_t> order(anchors_.size());
  std::iota(order.begin(), order.end(), size_t{0});
  RandomStream rng(RandomStream::deriveSeed(seed, "anchor_grid:unknown"));
  for (int k = 0; k < n_unknown; ++k) {
    const size_t pick = static_cast<size_t>(k) + static_cast<size_t>(rng.uniform() * static_cast<double>(order.size() - k));
    std::swap(order[static_cast<size_t>(k)], order[std::min(pick, order.size() - 1)]);
    anchors_[order[static_cast<size_t>(k)]].known = false;
  }
}

std::vector<SensorId> GridAnchorLayout::anchorsNear(int cell) const {
  std::vector<SensorId> out;
  for (int c : cells_.neighbourhood(cell)) {
    const auto& ids = by_cell_.at(static_cast<size_t>(c));
    out.insert(out.end(), ids.begin(), ids.end());
  }
  std::sort(out.begin(), out.end());
  return out;
}

int GridAnchorLayout::cellOfAnchor(SensorId id) const {
  const auto it = index_.find(id);
  if (it == index_.end()) throw std::out_of_range("GridAnchorLayout: no anchor " + std::to_string(id));
  return anchors_[it->second].cell;
}

std::map<SensorId, Eigen::Vector3d> GridAnchorLayout::positions() const {
  std::map<SensorId, Eigen::Vector3d> out;
  for (const GridAnchor& a : anchors_) out[a.id] = a.p_AinG;
  return out;
}

std::set<SensorId> GridAnchorLayout::knownIds() const {
  std::set<SensorId> out;
  for (const GridAnchor& a : anchors_)
    if (a.known) out.insert(a.id);
  return out;
}

int GridAnchorLayout::maxAnchorsPerCell() const {
  size_t n = 0;
  for (const auto& ids : by_cell_) n = std::max(n, ids.size());
  return static_cast<int>(n);
}

std::string GridAnchorLayout::toString() const {
  std::ostringstream s;
  int walls = 0, pillars = 0, ceiling = 0;
  for (const GridAnchor& a : anchors_)
    (a.mount == AnchorMount::Wall ? walls : a.mount == AnchorMount::Ceiling ? ceiling : pillars)++;
  s << anchors_.size() << " anchors on a " << g_x_ << " x " << g_y_ << " grid (" << walls << " on walls, " << pillars
    << " on pillars, " << ceiling << " on the ceiling), " << (anchors_.size() - knownIds().size()) << " fly-by; "
    << cells_.toString();
  return s.str();
}

}  // namespace meshnav::sim
