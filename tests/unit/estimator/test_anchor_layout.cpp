/// The known anchors' plan-view shape (AnchorLayout): spreads with exact answers, the line ratio
/// that flags horizontal positions nearly on one line whatever the heights, degenerate sets, and
/// the node's start-up warning counter (not for anchors in a wall of the flight volume).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "estimator/uwb/anchor_layout.h"
#include "node_test_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;

TEST(AnchorLayout, PlanSpreadsAndLineRatioHaveTheirExactValues) {
  // Plan view (±2, 0) and (0, ±0.2): RMS along x √(8/4) = √2, along y √(0.08/4) = √0.02. The
  // heights differ and do not count.
  const auto l = AnchorLayout::of({{101, {2, 0, 5}}, {102, {-2, 0, 6}}, {103, {0, 0.2, 2}}, {104, {0, -0.2, 5}}});
  ASSERT_TRUE(l.has_value());
  EXPECT_NEAR(l->planSpread_m()(0), std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(l->planSpread_m()(1), std::sqrt(0.02), 1e-12);
  EXPECT_NEAR(l->lineRatio(), 0.1, 1e-12);
  EXPECT_TRUE(l->nearlyCollinear());
  EXPECT_NEAR(std::abs(l->lineDirection_G().x()), 1.0, 1e-12);
  EXPECT_NEAR(std::abs(l->acrossLine_G().y()), 1.0, 1e-12);
  EXPECT_TRUE(l->centroid_G().isApprox(Eigen::Vector3d(0, 0, 4.5)));
  EXPECT_NE(l->describe().find("Place an anchor off the line"), std::string::npos) << l->describe();
}

TEST(AnchorLayout, AnchorsInOneVerticalPlaneAreFlaggedWhateverTheirHeights) {
  // In y = 0 at 6, 6 and 3 m: the 3D spread is far from a line (√6 / √2), the mirror y → −y is not.
  const auto l = AnchorLayout::of({{101, {-3, 0, 6}}, {102, {3, 0, 6}}, {103, {0, 0, 3}}});
  ASSERT_TRUE(l.has_value());
  EXPECT_NEAR(l->lineRatio(), 0.0, 1e-12);
  EXPECT_TRUE(l->nearlyCollinear());
  EXPECT_NEAR(std::abs(l->acrossLine_G().y()), 1.0, 1e-12);  // the mirror plane's normal, horizontal
}

TEST(AnchorLayout, SpreadAnchorsAreNotFlaggedAndDegenerateSetsAre) {
  // The cross with the short arm at ±0.5 m: ratio 0.25, just above the bound.
  const auto spread = AnchorLayout::of({{101, {2, 0, 5}}, {102, {-2, 0, 5}}, {103, {0, 0.5, 5}}, {104, {0, -0.5, 5}}});
  ASSERT_TRUE(spread.has_value());
  EXPECT_NEAR(spread->lineRatio(), 0.25, 1e-12);
  EXPECT_FALSE(spread->nearlyCollinear());
  EXPECT_EQ(spread->describe().find("off the line"), std::string::npos);
  const auto two = AnchorLayout::of({{101, {0, 0, 0}}, {102, {1, 2, 3}}});
  ASSERT_TRUE(two.has_value());
  EXPECT_NEAR(two->lineRatio(), 0.0, 1e-12);
  EXPECT_TRUE(two->nearlyCollinear());
  // Stacked at one horizontal position: worse than a line, and said so.
  const auto stacked = AnchorLayout::of({{101, {1, 1, 0}}, {102, {1, 1, 2}}, {103, {1.01, 1, 4}}});
  ASSERT_TRUE(stacked.has_value());
  EXPECT_TRUE(stacked->nearlyCollinear());
  EXPECT_NE(stacked->describe().find("one horizontal position"), std::string::npos) << stacked->describe();
  EXPECT_FALSE(AnchorLayout::of({{101, {0, 0, 0}}}).has_value());
  EXPECT_FALSE(AnchorLayout::of({}).has_value());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(AnchorLayout::of({{101, {0, 0, 0}}, {102, {nan, 1, 1}}, {103, {2, 0, 1}}}).has_value());
}

namespace {

/// The paper hall's synthetic setup with every known anchor placed by `place(i)`.
SystemSetup setupWithAnchors(const std::function<Eigen::Vector3d(int)>& place, bool volume) {
  synthetic::SyntheticOptions o;
  o.duration_s = 30.0;
  SystemSetup setup = synthetic::makeSyntheticDataset(o).setup;
  int i = 0;
  for (auto& [id, p] : setup.abs_anchor_positions) p = place(i++);
  setup.flight_volume.reset();
  if (volume) setup.flight_volume = FlightVolume{Eigen::Vector3d(-5, -4, 0), Eigen::Vector3d(5, 4, 6)};
  return setup;
}

int64_t collinearCount(const SystemSetup& setup) {
  EstimatorNode node(test::testOptions(), setup);
  return node.diagnostics().get("known_anchors_nearly_collinear");
}

}  // namespace

TEST(AnchorLayout, TheNodeWarnsOnceAtStartUnlessTheLineIsAWallOfTheVolume) {
  synthetic::SyntheticOptions o;
  o.duration_s = 30.0;
  const SystemSetup paper = synthetic::makeSyntheticDataset(o).setup;
  ASSERT_GE(paper.abs_anchor_positions.size(), 3u);
  EXPECT_EQ(collinearCount(paper), 0);  // the paper's hall: spread anchors
  // On one ceiling line, 5 cm either side of it: the vertical plane through it cuts the volume.
  const auto ceiling = [](int i) { return Eigen::Vector3d(-3.0 + 1.5 * i, i % 2 ? 0.05 : -0.05, 6.0); };
  EXPECT_EQ(collinearCount(setupWithAnchors(ceiling, true)), 1);
  EXPECT_EQ(collinearCount(setupWithAnchors(ceiling, false)), 1);
  // On the wall y = 4 m at several heights: the volume tells the image behind the wall apart ...
  const auto wall = [](int i) { return Eigen::Vector3d(-3.0 + 1.5 * i, 4.0, i % 2 ? 1.0 : 4.0); };
  EXPECT_EQ(collinearCount(setupWithAnchors(wall, true)), 0);
  // ... and without a volume nothing does.
  EXPECT_EQ(collinearCount(setupWithAnchors(wall, false)), 1);
}
