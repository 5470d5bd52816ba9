// What the one calibrator of a fleet hears and says (pipeline/fleet_calibrator_feed.h): the same
// object runs in meshnav_run --fleet and behind `calibrator --fleet` over LCM.
#include <gtest/gtest.h>

#include "pipeline/anchor_belief_intersection.h"
#include "fleet_test_data.h"
#include "pipeline/fleet.h"
#include "pipeline/fleet_calibrator_feed.h"

using namespace meshnav;
using namespace meshnav::pipeline;
using meshnav::pipeline::test::range;
using meshnav::pipeline::test::vehicleSetup;

namespace {

AnchorEstimate belief(SensorId id, double x, double var) {
  AnchorEstimate a;
  a.id = id;
  a.t = Timestamp::fromSec(1.0);
  a.p_AinG = {x, 0, 2};
  a.cov_p_m2 = var * Eigen::Matrix3d::Identity();
  return a;
}

/// Two vehicles: a with tags 10, 11; b with tag 20; the anchors 101, 102 known, 106 not.
struct TwoVehicles {
  std::vector<Vehicle> vehicles{{"a", vehicleSetup({{10, {0, 0, 0}}, {11, {0.5, 0, 0}}})},
                                {"b", vehicleSetup({{20, {0, 0, 0}}})}};
  SystemSetup fleet = mergeFleetSetups(vehicles, "test");
  Diagnostics diag;
};

}  // namespace

TEST(FleetCalibratorFeed, EveryTagBelongsToItsVehicle) {
  TwoVehicles f;
  FleetCalibratorFeed feed(f.vehicles, f.fleet, f.diag);
  EXPECT_EQ(feed.vehicleCount(), 2u);
  const std::map<SensorId, size_t> expected = {{10, 0}, {11, 0}, {20, 1}};
  EXPECT_EQ(feed.vehicleOfTag(), expected);
  // A vehicle whose tag the fleet's setup does not know is refused.
  std::vector<Vehicle> stray = f.vehicles;
  stray[1].setup.rel_tag_positions[30] = {0, 0, 0};
  EXPECT_THROW(FleetCalibratorFeed(stray, f.fleet, f.diag), std::invalid_argument);
}

TEST(FleetCalibratorFeed, TheAnchorsMeshOnceThoughEveryVehicleHeardIt) {
  TwoVehicles f;
  FleetCalibratorFeed feed(f.vehicles, f.fleet, f.diag);
  EXPECT_TRUE(feed.forCalibrator(range(5.0, 101, 106)));   // a's copy
  EXPECT_FALSE(feed.forCalibrator(range(5.0, 106, 101)));  // b's copy of the same exchange, either order
  EXPECT_EQ(f.diag.get("mesh_range_from_another_vehicle"), 1);
  EXPECT_TRUE(feed.forCalibrator(range(5.1, 101, 106)));   // the next exchange
  // Tag ranges are each vehicle's own: never taken for copies, even at one instant.
  EXPECT_TRUE(feed.forCalibrator(range(6.0, 10, 106)));
  EXPECT_TRUE(feed.forCalibrator(range(6.0, 10, 106)));
  // Forgotten after 10 s: the same stamp much later is a new range (a restarted recording).
  EXPECT_TRUE(feed.forCalibrator(range(20.0, 101, 102)));
  EXPECT_TRUE(feed.forCalibrator(range(5.0, 101, 106)));
  EXPECT_EQ(f.diag.get("mesh_range_from_another_vehicle"), 1);
}

TEST(FleetCalibratorFeed, RangesBetweenTwoVehiclesAreNoCalibratorInput) {
  TwoVehicles f;
  FleetCalibratorFeed feed(f.vehicles, f.fleet, f.diag);
  EXPECT_TRUE(feed.betweenVehicles(range(1.0, 10, 20)));
  EXPECT_FALSE(feed.betweenVehicles(range(1.0, 10, 11)));  // one vehicle's two tags
  EXPECT_FALSE(feed.betweenVehicles(range(1.0, 20, 106)));
  EXPECT_FALSE(feed.forCalibrator(range(1.0, 20, 10)));
  EXPECT_EQ(f.diag.get("inter_vehicle_range_not_for_calibrator"), 1);
}

TEST(FleetCalibratorFeed, TheCalibratorGetsTheIntersectionOfEveryVehiclesLatestBelief) {
  TwoVehicles f;
  FleetCalibratorFeed feed(f.vehicles, f.fleet, f.diag);
  // Only a has a belief of 106: it goes through as it is.
  auto out = feed.anchorsFrom(0, {belief(106, 1.0, 0.04)});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].p_AinG, Eigen::Vector3d(1.0, 0, 2));
  // b's belief, tighter: the CI of the two lies between them and is no tighter than the tighter one.
  out = feed.anchorsFrom(1, {belief(106, 1.2, 0.01)});
  ASSERT_EQ(out.size(), 1u);
  const GaussianBelief3 ci = AnchorBeliefIntersection::fuse({{1.0, 0, 2}, 0.04 * Eigen::Matrix3d::Identity()},
                                                            {{1.2, 0, 2}, 0.01 * Eigen::Matrix3d::Identity()});
  EXPECT_NEAR((out[0].p_AinG - ci.mean).norm(), 0.0, 1e-12);
  EXPECT_GE(out[0].cov_p_m2.trace(), 0.03 - 1e-12);
  // a's next ANCHORS replaces its earlier one (latest only): a now agrees with b exactly.
  out = feed.anchorsFrom(0, {belief(106, 1.2, 0.01)});
  EXPECT_NEAR(out[0].p_AinG.x(), 1.2, 1e-12);
  EXPECT_THROW(feed.anchorsFrom(2, {}), std::out_of_range);
}

TEST(FleetCalibratorFeed, EachVehicleGetsTheAnchorInitWithoutTheOthersTags) {
  TwoVehicles f;
  FleetCalibratorFeed feed(f.vehicles, f.fleet, f.diag);
  AnchorInit init;
  init.id = 106;
  for (SensorId ref : {10, 20, 101}) init.biases.push_back({ref, 106, 0.1, 1.0, 0.1, 0.0});
  init.cov_gamma_p_m2 = Eigen::MatrixXd::Zero(3, 3);
  init.cov_gamma_m2 = 0.01 * Eigen::MatrixXd::Identity(3, 3);
  const AnchorInit to_a = feed.forVehicle(0, init), to_b = feed.forVehicle(1, init);
  ASSERT_EQ(to_a.biases.size(), 2u);
  EXPECT_EQ(to_a.biases[0].a, 10);
  EXPECT_EQ(to_a.biases[1].a, 101);
  ASSERT_EQ(to_b.biases.size(), 2u);
  EXPECT_EQ(to_b.biases[0].a, 20);
  EXPECT_EQ(to_b.biases[1].a, 101);
}

TEST(FleetCalibratorFeed, OneVehiclePassesEverythingThrough) {
  const SystemSetup s = vehicleSetup({{10, {0, 0, 0}}});
  Diagnostics diag;
  FleetCalibratorFeed feed({{"", s}}, s, diag);
  EXPECT_TRUE(feed.forCalibrator(range(5.0, 101, 106)));
  EXPECT_TRUE(feed.forCalibrator(range(5.0, 101, 106)));  // a duplicate is the calibrator's to count
  const auto out = feed.anchorsFrom(0, {belief(106, 1.0, 0.04), belief(107, 2.0, 0.04)});
  EXPECT_EQ(out.size(), 2u);
  AnchorInit init;
  init.id = 106;
  init.biases.push_back({10, 106, 0.1, 1.0, 0.1, 0.0});
  EXPECT_EQ(feed.forVehicle(0, init).biases.size(), 1u);
  EXPECT_EQ(diag.total(), 0);
}
