#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <stdexcept>

#include "sim/grid_anchor_layout.h"
#include "sim/scaled_fleet_simulation.h"

using namespace meshnav::sim;
using meshnav::SensorId;

namespace {
ScaledFleetOptions small() {
  ScaledFleetOptions o;
  o.base.seed = 4;
  o.base.hall_size_m = Eigen::Vector3d(24, 24, 8);
  o.base.duration_s = 40.0;
  o.n_vehicles = 3;
  o.n_anchors = 36;
  return o;
}
}  // namespace

TEST(SimScaledFleet, VehiclesShareOneWorldAndEachFileHoldsItsOwnTagsAndTheMesh) {
  const ScaledFleetOptions o = small();
  const ScaledFleet f = simulateScaledFleet(o);
  ASSERT_EQ(f.vehicles.size(), 3u);
  const GridAnchorLayout layout(Hall::ofSize({24, 24, 8}), 36, 7, {99, 100, 105, 1099, 1100, 1105, 2099, 2100, 2105}, 4);
  std::set<std::string> kinds;
  for (size_t k = 0; k < 3; ++k) {
    const auto& ds = f.vehicles[k].dataset;
    kinds.insert(f.vehicles[k].trajectory_kind);
    EXPECT_EQ(ds.setup.abs_anchor_positions.size(), 36u - 7u);  // 20 % fly-by
    EXPECT_EQ(ds.truth->anchor_positions.size(), 36u);
    EXPECT_EQ(ds.setup.rel_tag_positions.count(100 + 1000 * static_cast<SensorId>(k)), 1u);
    EXPECT_EQ(ds.setup.abs_anchor_positions, f.vehicles[0].dataset.setup.abs_anchor_positions);
    ASSERT_TRUE(ds.setup.flight_volume.has_value());
    // Its flight stays in its region.
    for (const auto& g : ds.ground_truth) EXPECT_TRUE(f.regions[k].contains(g.p_IinG, 0.2, 0.0, 0.2)) << k;
    EXPECT_TRUE(std::is_sorted(ds.ranges.begin(), ds.ranges.end(), [](const auto& a, const auto& b) { return a.t < b.t; }));
    int own = 0, mesh = 0;
    for (const auto& r : ds.ranges) {
      if (r.type_initiator == meshnav::UwbType::Tag) {
        EXPECT_EQ(r.id_initiator / 1000, static_cast<SensorId>(k)) << "another vehicle's tag in v" << k;
        ++own;
      } else {
        ++mesh;
      }
    }
    // Two tags: 4 cell slots and 1 peer slot each per 0.38 s frame (10 fleet tags), with drops and seat waits.
    EXPECT_NEAR(own / 40.0, 2 * (4 + 1) / 0.38, 3.0);
    EXPECT_GT(mesh, 1000);
    // Pair biases of pairs that can range only: a tag's with every known anchor, two anchors of
    // neighbouring cells.
    int tag_pairs = 0;
    for (const auto& b : ds.setup.pair_biases) {
      const bool tag = b.a % 1000 == 100 || b.a % 1000 == 105 || b.b % 1000 == 100 || b.b % 1000 == 105;
      tag_pairs += tag ? 1 : 0;
      if (!tag) EXPECT_TRUE(layout.cells().neighbours(layout.cellOfAnchor(b.a), layout.cellOfAnchor(b.b))) << b.a << "-" << b.b;
    }
    EXPECT_EQ(tag_pairs, 2 * 29 + 1);  // and the pair of its own two tags
  }
  EXPECT_EQ(kinds.size(), 3u);  // three different flights
  EXPECT_NE(f.mission_yaml.find("{t: 22, action: calibrate}"), std::string::npos) << f.mission_yaml;
  EXPECT_NE(f.mission_yaml.find("{t: 30, action: calibrate}"), std::string::npos) << f.mission_yaml;
  EXPECT_EQ(std::count(f.layout_csv.begin(), f.layout_csv.end(), '\n'), 37);
  // Deterministic.
  const ScaledFleet again = simulateScaledFleet(o);
  EXPECT_EQ(again.vehicles[2].dataset.ranges.size(), f.vehicles[2].dataset.ranges.size());
  EXPECT_EQ(again.vehicles[2].dataset.imu.back().acc_m_s2, f.vehicles[2].dataset.imu.back().acc_m_s2);
}

TEST(SimScaledFleet, RegionsSpreadOverTheHallAndBadOptionsAreRefused) {
  const Hall hall = Hall::ofSize({40, 40, 10});
  for (int k = 0; k < 5; ++k) {
    const Hall r = scaledFleetRegion(hall, k, 5, 0.6, 0.3);
    EXPECT_NEAR(r.size().x(), 24.0, 1e-9);
    EXPECT_TRUE(hall.contains(r.min_m, 0, 0, 0) && hall.contains(r.max_m, 0, 0, 0)) << k;
  }
  EXPECT_TRUE(scaledFleetRegion(hall, 0, 1, 0.6, 0.3).center().isApprox(hall.center()));
  ScaledFleetOptions o = small();
  o.n_vehicles = 17;
  EXPECT_THROW(simulateScaledFleet(o), std::invalid_argument);
  o = small();
  o.outage.vehicle = 3;
  o.outage.t1_s = 5.0;
  EXPECT_THROW(simulateScaledFleet(o), std::invalid_argument);
  o = small();
  o.n_fly_by = 34;
  EXPECT_THROW(simulateScaledFleet(o), std::invalid_argument);
}
