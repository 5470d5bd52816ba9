/// The known anchors' shape (AnchorLayout): principal spreads with exact answers, the line ratio
/// that flags nearly collinear anchors, and the node's warning counter at start.
#include <gtest/gtest.h>

#include <cmath>

#include "estimator/uwb/anchor_layout.h"
#include "node_test_helpers.h"

using namespace meshnav;
using namespace meshnav::estimator;

TEST(AnchorLayout, SpreadsAndLineRatioHaveTheirExactValues) {
  // (±2, 0, 5) and (0, ±0.2, 5): RMS along x √(8/4) = √2, along y √(0.08/4) = √0.02, none along z.
  const auto l = AnchorLayout::of({{101, {2, 0, 5}}, {102, {-2, 0, 5}}, {103, {0, 0.2, 5}}, {104, {0, -0.2, 5}}});
  ASSERT_TRUE(l.has_value());
  EXPECT_NEAR(l->rmsSpread_m()(0), std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(l->rmsSpread_m()(1), std::sqrt(0.02), 1e-12);
  EXPECT_NEAR(l->rmsSpread_m()(2), 0.0, 1e-12);
  EXPECT_NEAR(l->lineRatio(), 0.1, 1e-12);
  EXPECT_TRUE(l->nearlyCollinear());
  EXPECT_NEAR(std::abs(l->lineDirection_G().x()), 1.0, 1e-12);
  EXPECT_TRUE(l->centroid_G().isApprox(Eigen::Vector3d(0, 0, 5)));
  EXPECT_NE(l->describe().find("Place an anchor off the line"), std::string::npos) << l->describe();
}

TEST(AnchorLayout, SpreadAnchorsAreNotCollinearAndTwoAlwaysAre) {
  // The same cross with the short arm at ±0.5 m: ratio 0.25, just above the bound.
  const auto spread = AnchorLayout::of({{101, {2, 0, 5}}, {102, {-2, 0, 5}}, {103, {0, 0.5, 5}}, {104, {0, -0.5, 5}}});
  ASSERT_TRUE(spread.has_value());
  EXPECT_NEAR(spread->lineRatio(), 0.25, 1e-12);
  EXPECT_FALSE(spread->nearlyCollinear());
  EXPECT_EQ(spread->describe().find("off the line"), std::string::npos);
  const auto two = AnchorLayout::of({{101, {0, 0, 0}}, {102, {1, 2, 3}}});
  ASSERT_TRUE(two.has_value());
  EXPECT_NEAR(two->lineRatio(), 0.0, 1e-12);
  EXPECT_TRUE(two->nearlyCollinear());
  EXPECT_FALSE(AnchorLayout::of({{101, {0, 0, 0}}}).has_value());
  EXPECT_FALSE(AnchorLayout::of({}).has_value());
}

TEST(AnchorLayout, TheNodeCountsNearlyCollinearKnownAnchorsAtStart) {
  synthetic::SyntheticOptions o;
  o.duration_s = 30.0;
  Dataset ds = synthetic::makeSyntheticDataset(o);
  ASSERT_GE(ds.setup.abs_anchor_positions.size(), 3u);
  {
    EstimatorNode node(test::testOptions(), ds.setup);  // the paper's hall: spread anchors
    EXPECT_EQ(node.diagnostics().get("known_anchors_nearly_collinear"), 0);
  }
  // Every known anchor moved onto one ceiling line, 5 cm apart across it.
  int i = 0;
  for (auto& [id, p] : ds.setup.abs_anchor_positions) {
    p = Eigen::Vector3d(-3.0 + 1.5 * i, (i % 2 ? 0.05 : -0.05), 6.0);
    ++i;
  }
  EstimatorNode node(test::testOptions(), ds.setup);
  EXPECT_EQ(node.diagnostics().get("known_anchors_nearly_collinear"), 1);
}
