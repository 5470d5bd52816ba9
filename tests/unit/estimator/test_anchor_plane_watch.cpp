/// AnchorPlaneWatch: when known anchors count as coplanar, and when the estimate's side of their
/// plane changes (with hysteresis).
#include <gtest/gtest.h>

#include "estimator/node/anchor_plane_watch.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {
std::map<SensorId, Eigen::Vector3d> oneWall() {  // three anchors on the wall x = 5.5 (seed-4 run050)
  return {{101, {5.5, -2.18, 0.63}}, {102, {5.5, -0.61, 5.07}}, {103, {5.5, 2.30, 2.13}}};
}
}  // namespace

TEST(AnchorPlaneWatch, ThreeAnchorsAreAlwaysAPlaneFourSpreadOnesAreNot) {
  const auto w = AnchorPlaneWatch::of(oneWall());
  ASSERT_TRUE(w);
  EXPECT_NEAR(std::abs(w->normal().x()), 1.0, 1e-9);
  EXPECT_NEAR(std::abs(w->distance({4.45, 0.0, 1.9})), 1.05, 1e-9);
  auto spread = oneWall();
  spread[104] = {-4.0, 0.0, 2.0};  // the far wall: 4.5 m RMS off any plane through the others
  EXPECT_FALSE(AnchorPlaneWatch::of(spread));
  auto near_plane = oneWall();
  near_plane[104] = {5.3, 0.5, 3.0};  // 0.2 m off the wall: 0.087 m RMS, still one plane
  EXPECT_TRUE(AnchorPlaneWatch::of(near_plane));
  EXPECT_FALSE(AnchorPlaneWatch::of({{1, {0, 0, 0}}, {2, {1, 0, 0}}}));
  EXPECT_FALSE(AnchorPlaneWatch::of({{1, {0, 0, 0}}, {2, {1, 0, 0}}, {3, {2, 0, 0}}}));  // a line spans no plane
}

TEST(AnchorPlaneWatch, ACrossingCountsOnceBeyondTheHysteresis) {
  auto w = *AnchorPlaneWatch::of(oneWall());
  EXPECT_FALSE(w.crossed({4.45, 0.0, 1.9}));  // the first position only sets the side
  EXPECT_FALSE(w.crossed({5.0, 0.0, 1.9}));
  EXPECT_FALSE(w.crossed({5.55, 0.0, 1.9}));  // within 0.1 m of the plane: no side
  EXPECT_FALSE(w.crossed({5.45, 0.0, 1.9}));
  EXPECT_TRUE(w.crossed({5.65, 0.0, 1.9}));   // beyond it on the other side
  EXPECT_FALSE(w.crossed({6.4, 0.0, 1.9}));   // once
  EXPECT_TRUE(w.crossed({5.0, 0.0, 1.9}));    // and back
  w.reset();
  EXPECT_FALSE(w.crossed({6.0, 0.0, 1.9}));   // a replaced pose sets its side afresh
}
