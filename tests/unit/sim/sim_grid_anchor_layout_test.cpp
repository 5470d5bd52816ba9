#include <gtest/gtest.h>

#include <map>
#include <set>
#include <stdexcept>

#include "sim/grid_anchor_layout.h"

using namespace meshnav::sim;

namespace {
const std::set<meshnav::SensorId> kFleetTags{99, 100, 105, 1099, 1100, 1105};

const GridAnchor& byId(const GridAnchorLayout& l, meshnav::SensorId id) {
  for (const GridAnchor& a : l.anchors())
    if (a.id == id) return a;
  throw std::out_of_range("no anchor");
}
}  // namespace

TEST(SimGridAnchorLayout, AHundredAnchorsInAFortyMetreHallAreWhereTheDocsSay) {
  const GridAnchorLayout l(Hall::ofSize({40, 40, 10}), 100, 20, kFleetTags, 1);
  ASSERT_EQ(l.anchors().size(), 100u);
  EXPECT_EQ(l.pointsX(), 10);
  EXPECT_EQ(l.pointsY(), 10);
  EXPECT_EQ(l.cells().cellsX(), 5);
  EXPECT_EQ(l.cells().cellsY(), 5);
  // Ids from 101, skipping the tag id 105.
  EXPECT_EQ(l.anchors()[0].id, 101);
  EXPECT_EQ(l.anchors()[4].id, 106);
  EXPECT_EQ(l.anchors()[99].id, 201);
  // A corner on two walls, low; the wall along y = -20; a ceiling and a pillar anchor inside.
  EXPECT_TRUE(byId(l, 101).p_AinG.isApprox(Eigen::Vector3d(-19.9, -19.9, 1.0)));
  EXPECT_EQ(byId(l, 101).mount, AnchorMount::Wall);
  EXPECT_TRUE(byId(l, 102).p_AinG.isApprox(Eigen::Vector3d(-14.0, -19.9, 3.5)));
  EXPECT_TRUE(byId(l, 113).p_AinG.isApprox(Eigen::Vector3d(-14.0, -14.0, 9.7)));  // point (1, 1)
  EXPECT_EQ(byId(l, 113).mount, AnchorMount::Ceiling);
  EXPECT_TRUE(byId(l, 114).p_AinG.isApprox(Eigen::Vector3d(-10.0, -14.0, 6.5)));  // point (2, 1)
  EXPECT_EQ(byId(l, 114).mount, AnchorMount::Pillar);
  std::map<AnchorMount, int> mounts;
  for (const GridAnchor& a : l.anchors()) ++mounts[a.mount];
  EXPECT_EQ(mounts[AnchorMount::Wall], 36);
  EXPECT_EQ(mounts[AnchorMount::Pillar], 48);
  EXPECT_EQ(mounts[AnchorMount::Ceiling], 16);
  // Every cell holds 2 x 2 anchors at the four heights.
  EXPECT_EQ(l.maxAnchorsPerCell(), 4);
  for (int c = 0; c < l.cells().cellCount(); ++c) {
    ASSERT_EQ(l.anchorsOfCell(c).size(), 4u) << c;
    std::set<double> heights;
    for (auto id : l.anchorsOfCell(c)) heights.insert(byId(l, id).p_AinG.z());
    EXPECT_EQ(heights, (std::set<double>{1.0, 3.5, 6.5, 9.7})) << c;
  }
  EXPECT_EQ(l.cellOfAnchor(101), 0);
  EXPECT_EQ(l.cellOfAnchor(113), 0);
  EXPECT_EQ(l.anchorsNear(0).size(), 16u);
  EXPECT_EQ(l.anchorsNear(12).size(), 36u);
  EXPECT_THROW(l.cellOfAnchor(105), std::out_of_range);
}

TEST(SimGridAnchorLayout, FlyByAnchorsAreASeededDrawOfTheRequestedCount) {
  const Hall hall = Hall::ofSize({40, 40, 10});
  const GridAnchorLayout a(hall, 100, 20, kFleetTags, 1), b(hall, 100, 20, kFleetTags, 1), c(hall, 100, 20, kFleetTags, 2);
  EXPECT_EQ(a.knownIds().size(), 80u);
  EXPECT_EQ(a.knownIds(), b.knownIds());
  EXPECT_NE(a.knownIds(), c.knownIds());
  EXPECT_EQ(a.positions(), c.positions());  // the seed picks the fly-by anchors, not the places
  EXPECT_EQ(GridAnchorLayout(hall, 100, 0, kFleetTags, 1).knownIds().size(), 100u);
}

TEST(SimGridAnchorLayout, OtherCountsFillTheGridRowByRowAndBadCountsAreRefused) {
  const GridAnchorLayout l(Hall::ofSize({16, 16, 6}), 16, 4, kFleetTags, 3);
  EXPECT_EQ(l.pointsX(), 4);
  EXPECT_EQ(l.pointsY(), 4);
  EXPECT_EQ(l.cells().cellCount(), 4);
  EXPECT_EQ(l.maxAnchorsPerCell(), 4);
  for (const GridAnchor& a : l.anchors()) EXPECT_TRUE(Hall::ofSize({16, 16, 6}).contains(a.p_AinG, 0, 0, 0)) << a.id;
  const GridAnchorLayout odd(Hall::ofSize({30, 20, 8}), 10, 2, kFleetTags, 3);
  EXPECT_EQ(odd.anchors().size(), 10u);
  EXPECT_EQ(odd.pointsX(), 4);  // round(sqrt(10 * 1.5))
  EXPECT_EQ(odd.pointsY(), 3);
  EXPECT_THROW(GridAnchorLayout(Hall::ofSize({16, 16, 6}), 3, 0, kFleetTags, 1), std::invalid_argument);
  EXPECT_THROW(GridAnchorLayout(Hall::ofSize({16, 16, 6}), 16, 14, kFleetTags, 1), std::invalid_argument);
}
