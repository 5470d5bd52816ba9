#include "sim/anchor_layout.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include "sim/enum_names.h"
#include "sim/paper_scenario.h"
#include "sim/random_stream.h"

namespace meshnav::sim {

namespace {

constexpr EnumNameTable<AnchorLayoutKind, 5> kNames{{{AnchorLayoutKind::Paper, "paper"},
                                                     {AnchorLayoutKind::Walls, "walls"},
                                                     {AnchorLayoutKind::OneWall, "one-wall"},
                                                     {AnchorLayoutKind::Ceiling, "ceiling"},
                                                     {AnchorLayoutKind::Random, "random"}}};
constexpr double kWallInset_m = 0.1;   ///< anchors hang this far inside the wall
constexpr double kEdgeMargin_m = 0.3;  ///< from corners, floor and ceiling

/// Point on wall `w` (0: x = min, 1: x = max, 2: y = min, 3: y = max) at `along` ∈ [0, 1] of the
/// usable wall length and height z [m].
Eigen::Vector3d onWall(const Hall& hall, int w, double along, double z_m) {
  const int axis = w < 2 ? 0 : 1;  // the wall's normal axis
  const int other = 1 - axis;
  Eigen::Vector3d p;
  p[axis] = (w % 2 == 0) ? hall.min_m[axis] + kWallInset_m : hall.max_m[axis] - kWallInset_m;
  p[other] = hall.min_m[other] + kEdgeMargin_m + along * (hall.size()[other] - 2.0 * kEdgeMargin_m);
  p.z() = z_m;
  return p;
}

double wallHeight(const Hall& hall, RandomStream& rng) {
  return rng.uniform(hall.min_m.z() + kEdgeMargin_m, hall.max_m.z() - kEdgeMargin_m);
}

/// Uniform in the volume, then pulled to 0.1–1 m from the nearest side wall.
Eigen::Vector3d nearWall(const Hall& hall, RandomStream& rng) {
  Eigen::Vector3d p(rng.uniform(hall.min_m.x(), hall.max_m.x()), rng.uniform(hall.min_m.y(), hall.max_m.y()),
                    rng.uniform(hall.min_m.z() + 0.2, hall.max_m.z() - 0.2));
  const std::array<double, 4> d{p.x() - hall.min_m.x(), hall.max_m.x() - p.x(), p.y() - hall.min_m.y(),
                                hall.max_m.y() - p.y()};
  const int w = static_cast<int>(std::min_element(d.begin(), d.end()) - d.begin());
  const int axis = w < 2 ? 0 : 1;
  const double dist = std::min(rng.uniform(0.1, 1.0), 0.5 * hall.size()[axis]);
  p[axis] = (w % 2 == 0) ? hall.min_m[axis] + dist : hall.max_m[axis] - dist;
  return p;
}

/// The paper's anchors, known-first order, mapped into `hall`.
std::vector<Eigen::Vector3d> paperPositions(const Hall& hall, size_t n) {
  const PaperScenario paper = PaperScenario::paper();
  const Hall from = Hall::paper();
  const bool same = hall.min_m == from.min_m && hall.max_m == from.max_m;
  const Eigen::Vector3d scale = hall.size().cwiseQuotient(from.size());
  std::vector<Eigen::Vector3d> out;
  for (SensorId id : {101, 102, 103, 104, 106, 107, 108, 109, 110}) {
    const Eigen::Vector3d& p = paper.anchors_p_AinG.at(id);
    out.push_back(same ? p : Eigen::Vector3d(hall.min_m + (p - from.min_m).cwiseProduct(scale)));
    if (out.size() == n) break;
  }
  return out;
}

std::vector<Eigen::Vector3d> generatedPositions(AnchorLayoutKind kind, const Hall& hall, int n_known, int n_unknown,
                                                RandomStream& rng) {
  std::vector<Eigen::Vector3d> out;
  const int first_wall = static_cast<int>(std::floor(rng.uniform(0.0, 4.0)));
  const double H = hall.size().z();
  for (int i = 0; i < n_known + n_unknown; ++i) {
    const bool known = i < n_known;
    const int other_wall = (first_wall + 1 + (i - n_known) % 3) % 4;  // the walls except first_wall
    switch (kind) {
      case AnchorLayoutKind::Walls:
        out.push_back(onWall(hall, (first_wall + i) % 4, rng.uniform(), wallHeight(hall, rng)));
        break;
      case AnchorLayoutKind::OneWall:
        if (known) {
          const double along = (i + rng.uniform(0.2, 0.8)) / n_known;
          const double z = (i % 2 == 0) ? rng.uniform(kEdgeMargin_m, 0.45 * H) : rng.uniform(0.55 * H, H - kEdgeMargin_m);
          out.push_back(onWall(hall, first_wall, along, hall.min_m.z() + z));
        } else {
          out.push_back(onWall(hall, other_wall, rng.uniform(), wallHeight(hall, rng)));
        }
        break;
      case AnchorLayoutKind::Ceiling:
        if (known)
          out.emplace_back(rng.uniform(hall.min_m.x() + 0.5, hall.max_m.x() - 0.5),
                           rng.uniform(hall.min_m.y() + 0.5, hall.max_m.y() - 0.5), hall.max_m.z() - rng.uniform(0.15, 0.4));
        else
          out.push_back(onWall(hall, (first_wall + i) % 4, rng.uniform(), wallHeight(hall, rng)));
        break;
      case AnchorLayoutKind::Random: out.push_back(nearWall(hall, rng)); break;
      case AnchorLayoutKind::Paper: break;
    }
  }
  return out;
}

}  // namespace

std::string toString(AnchorLayoutKind kind) { return enumName(kNames, kind); }
std::optional<AnchorLayoutKind> parseAnchorLayoutKind(std::string_view name) { return parseEnumName(kNames, name); }
std::string anchorLayoutKindNames() { return enumNameList(kNames); }

AnchorLayout AnchorLayout::generate(AnchorLayoutKind kind, const Hall& hall, int n_known, int n_unknown,
                                    const std::set<SensorId>& tag_ids, uint64_t seed) {
  if (n_known < 1 || n_unknown < 0) throw std::invalid_argument("AnchorLayout: needs >= 1 known and >= 0 unknown anchors");
  AnchorLayout layout;
  if (kind == AnchorLayoutKind::Paper) {
    if (n_known + n_unknown > 9) throw std::invalid_argument("AnchorLayout: the paper layout has 9 anchors");
    const std::array<SensorId, 9> ids{101, 102, 103, 104, 106, 107, 108, 109, 110};
    const auto positions = paperPositions(hall, static_cast<size_t>(n_known + n_unknown));
    for (size_t i = 0; i < positions.size(); ++i) {
      layout.anchors_p_AinG[ids[i]] = positions[i];
      if (static_cast<int>(i) < n_known) layout.known_ids.insert(ids[i]);
    }
    return layout;
  }
  RandomStream rng(RandomStream::deriveSeed(seed, "anchor_layout:" + toString(kind)));
  const auto positions = generatedPositions(kind, hall, n_known, n_unknown, rng);
  SensorId id = 101;
  for (size_t i = 0; i < positions.size(); ++i, ++id) {
    while (tag_ids.count(id)) ++id;
    layout.anchors_p_AinG[id] = positions[i];
    if (static_cast<int>(i) < n_known) layout.known_ids.insert(id);
  }
  return layout;
}

}  // namespace meshnav::sim
