#pragma once
/// @file hall.h
/// @brief The flight hall: an axis-aligned box in G (z up, floor at z = 0) [m].

#include <Eigen/Core>
#include <string>

namespace meshnav::sim {

struct Hall {
  Eigen::Vector3d min_m{-2.5, -4.2, 0.0};  ///< lower corner [m] (the paper's hall by default)
  Eigen::Vector3d max_m{3.0, 4.2, 8.2};    ///< upper corner [m]

  /// The paper's hall (docs/scenarios.md).
  static Hall paper() { return Hall{}; }
  /// A hall of the given size [m], centred on x = y = 0, floor at z = 0.
  static Hall ofSize(const Eigen::Vector3d& size_m) {
    return Hall{Eigen::Vector3d(-0.5 * size_m.x(), -0.5 * size_m.y(), 0.0),
                Eigen::Vector3d(0.5 * size_m.x(), 0.5 * size_m.y(), size_m.z())};
  }
  Eigen::Vector3d size() const { return max_m - min_m; }
  Eigen::Vector3d center() const { return 0.5 * (min_m + max_m); }
  /// True when p is inside with at least `margin_xy_m` to the walls, `margin_floor_m` above the
  /// floor and `margin_ceiling_m` below the ceiling.
  bool contains(const Eigen::Vector3d& p, double margin_xy_m, double margin_floor_m, double margin_ceiling_m) const {
    return p.x() >= min_m.x() + margin_xy_m && p.x() <= max_m.x() - margin_xy_m && p.y() >= min_m.y() + margin_xy_m &&
           p.y() <= max_m.y() - margin_xy_m && p.z() >= min_m.z() + margin_floor_m && p.z() <= max_m.z() - margin_ceiling_m;
  }
  std::string toString() const;
};

}  // namespace meshnav::sim
