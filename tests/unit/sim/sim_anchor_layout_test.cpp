#include <gtest/gtest.h>

#include <stdexcept>

#include "sim/anchor_layout.h"
#include "sim/paper_scenario.h"

using namespace meshnav::sim;

namespace {
const std::set<meshnav::SensorId> kTags{99, 100, 105};
const AnchorLayoutKind kAll[] = {AnchorLayoutKind::Paper, AnchorLayoutKind::Walls, AnchorLayoutKind::OneWall,
                                 AnchorLayoutKind::Ceiling, AnchorLayoutKind::Random};

bool inside(const Hall& h, const Eigen::Vector3d& p) { return h.contains(p, 0.0, 0.0, 0.0); }
}  // namespace

TEST(SimAnchorLayout, EveryLayoutHasTheRequestedCountsInsideTheHall) {
  for (const Hall& hall : {Hall::paper(), Hall::ofSize({6, 6, 3}), Hall::ofSize({12, 10, 8})})
    for (AnchorLayoutKind kind : kAll)
      for (int n_known : {3, 4, 5})
        for (int n_unknown : {0, 4}) {
          const auto l = AnchorLayout::generate(kind, hall, n_known, n_unknown, kTags, 7);
          EXPECT_EQ(l.known_ids.size(), static_cast<size_t>(n_known)) << toString(kind);
          EXPECT_EQ(l.anchors_p_AinG.size(), static_cast<size_t>(n_known + n_unknown)) << toString(kind);
          for (const auto& [id, p] : l.anchors_p_AinG) {
            EXPECT_TRUE(inside(hall, p)) << toString(kind) << " " << id << " at " << p.transpose();
            EXPECT_GE(id, 101);
            EXPECT_EQ(kTags.count(id), 0u) << "anchor id collides with a tag";
          }
          for (auto id : l.known_ids) EXPECT_EQ(l.anchors_p_AinG.count(id), 1u);
        }
}

TEST(SimAnchorLayout, PaperLayoutIsThePapersAnchorsAndScalesWithTheHall) {
  const auto paper = PaperScenario::paper();
  const auto l = AnchorLayout::generate(AnchorLayoutKind::Paper, Hall::paper(), 4, 5, {100, 105}, 1);
  EXPECT_EQ(l.anchors_p_AinG, paper.anchors_p_AinG);
  EXPECT_EQ(l.known_ids, paper.known_anchor_ids);
  const Hall big = Hall::ofSize({11.0, 16.8, 16.4});  // twice the paper's hall
  const auto s = AnchorLayout::generate(AnchorLayoutKind::Paper, big, 4, 5, {100, 105}, 1);
  const Eigen::Vector3d d_paper = paper.anchors_p_AinG.at(102) - paper.anchors_p_AinG.at(101);
  EXPECT_LT((s.anchors_p_AinG.at(102) - s.anchors_p_AinG.at(101) - 2.0 * d_paper).norm(), 1e-9);
  EXPECT_THROW(AnchorLayout::generate(AnchorLayoutKind::Paper, big, 5, 5, {}, 1), std::invalid_argument);
}

TEST(SimAnchorLayout, OneWallPutsTheKnownAnchorsOnOneWallSpreadInHeight) {
  const Hall hall = Hall::ofSize({10, 8, 4});
  for (uint64_t seed : {1u, 2u, 3u, 4u, 5u}) {
    const auto l = AnchorLayout::generate(AnchorLayoutKind::OneWall, hall, 4, 5, kTags, seed);
    // The one coordinate shared by all known anchors: 0.1 m inside one of the four walls.
    int walls_shared = 0;
    for (int axis = 0; axis < 2; ++axis)
      for (double wall : {hall.min_m[axis] + 0.1, hall.max_m[axis] - 0.1}) {
        bool all = true;
        for (auto id : l.known_ids) all = all && std::abs(l.anchors_p_AinG.at(id)[axis] - wall) < 1e-9;
        walls_shared += all;
      }
    EXPECT_EQ(walls_shared, 1) << "seed " << seed;
    double z_min = 1e9, z_max = -1e9;
    for (auto id : l.known_ids) z_min = std::min(z_min, l.anchors_p_AinG.at(id).z()), z_max = std::max(z_max, l.anchors_p_AinG.at(id).z());
    EXPECT_GT(z_max - z_min, 0.1 * hall.size().z()) << "seed " << seed;
  }
}

TEST(SimAnchorLayout, CeilingAndWallsAndRandomPlaceAsDocumented) {
  const Hall hall = Hall::ofSize({10, 8, 5});
  const auto c = AnchorLayout::generate(AnchorLayoutKind::Ceiling, hall, 5, 3, kTags, 2);
  for (auto id : c.known_ids) EXPECT_GT(c.anchors_p_AinG.at(id).z(), 5.0 - 0.41);
  const auto w = AnchorLayout::generate(AnchorLayoutKind::Walls, hall, 4, 4, kTags, 2);
  std::set<int> walls;
  for (const auto& [id, p] : w.anchors_p_AinG) {
    const double dx = std::min(p.x() - hall.min_m.x(), hall.max_m.x() - p.x());
    const double dy = std::min(p.y() - hall.min_m.y(), hall.max_m.y() - p.y());
    EXPECT_NEAR(std::min(dx, dy), 0.1, 1e-9);
    walls.insert(dx < dy ? (p.x() < 0 ? 0 : 1) : (p.y() < 0 ? 2 : 3));
  }
  EXPECT_EQ(walls.size(), 4u);  // all four walls used
  const auto r = AnchorLayout::generate(AnchorLayoutKind::Random, hall, 4, 4, kTags, 2);
  for (const auto& [id, p] : r.anchors_p_AinG) {
    const double d = std::min({p.x() - hall.min_m.x(), hall.max_m.x() - p.x(), p.y() - hall.min_m.y(), hall.max_m.y() - p.y()});
    EXPECT_GE(d, 0.1 - 1e-9);
    EXPECT_LE(d, 1.0 + 1e-9);
  }
}

TEST(SimAnchorLayout, SeedDeterminesTheLayoutAndNamesParse) {
  const Hall hall = Hall::ofSize({10, 8, 4});
  const auto a = AnchorLayout::generate(AnchorLayoutKind::Walls, hall, 4, 4, kTags, 3);
  const auto b = AnchorLayout::generate(AnchorLayoutKind::Walls, hall, 4, 4, kTags, 3);
  const auto c = AnchorLayout::generate(AnchorLayoutKind::Walls, hall, 4, 4, kTags, 4);
  EXPECT_EQ(a.anchors_p_AinG, b.anchors_p_AinG);
  EXPECT_NE(a.anchors_p_AinG, c.anchors_p_AinG);
  for (AnchorLayoutKind k : kAll) EXPECT_EQ(parseAnchorLayoutKind(toString(k)), k);
  EXPECT_FALSE(parseAnchorLayoutKind("wall").has_value());
}
