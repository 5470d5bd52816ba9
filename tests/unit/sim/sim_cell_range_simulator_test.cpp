#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>

#include "sim/cell_range_simulator.h"
#include "sim/paper_scenario.h"

using namespace meshnav::sim;
using meshnav::SensorId;

namespace {

/// A vehicle at rest at one point (what the ranging needs of a trajectory).
class StillTrajectory : public Trajectory {
 public:
  explicit StillTrajectory(const Eigen::Vector3d& p) : p_(p) {}
  TrajectoryState evaluate(double t_s) const override {
    TrajectoryState s;
    s.t_s = t_s;
    s.p_IinG = p_;
    return s;
  }
  double duration() const override { return 20.0; }
  std::string kind() const override { return "still"; }
  std::string toString() const override { return "still"; }

 private:
  Eigen::Vector3d p_;
};

struct World {
  Hall hall = Hall::ofSize({40, 40, 10});
  std::set<SensorId> tags{100, 105, 1100, 1105, 2100, 2105};
  GridAnchorLayout layout{hall, 100, 20, {99, 100, 105, 1099, 1100, 1105, 2099, 2100, 2105}, 1};
  std::vector<StillTrajectory> still;
  std::vector<CellVehicle> vehicles;
  std::unique_ptr<UwbHardwareBiases> biases;

  explicit World(std::vector<Eigen::Vector3d> places) {
    for (const auto& p : places) still.emplace_back(p);
    std::vector<SensorId> devices;
    for (const GridAnchor& a : layout.anchors()) devices.push_back(a.id);
    const auto lever = PaperScenario::paper().tags_p_TinI;
    for (size_t k = 0; k < still.size(); ++k) {
      CellVehicle v;
      v.trajectory = &still[k];
      v.t_end_s = 20.0;
      for (SensorId t : {100, 105}) {
        v.tags_p_TinI[t + 1000 * static_cast<SensorId>(k)] = lever.at(t);
        devices.push_back(t + 1000 * static_cast<SensorId>(k));
      }
      vehicles.push_back(v);
    }
    biases = std::make_unique<UwbHardwareBiases>(devices);
  }
  /// `peer_phase`: the schedule has the fleet's peer phase (CellTdmaSchedule's n_fleet_tags).
  CellRanges simulate(const UwbRangeOptions& uwb, CellOutage outage = {}, CellTdmaOptions tdma = {},
                      bool peer_phase = false) const {
    const int n_tags = peer_phase ? static_cast<int>(2 * vehicles.size()) : 0;
    const CellTdmaSchedule schedule(layout.cells().colourCount(), tdma, 0.0005, n_tags);
    return CellRangeSimulator(layout, vehicles, *biases, uwb, schedule, 7, outage).simulate(20.0);
  }
  bool isTag(SensorId id) const { return id >= 100 && (id % 1000 == 100 || id % 1000 == 105); }
};

UwbRangeOptions exact() {
  UwbRangeOptions o;
  o.sigma_range_m = 0.0;
  o.outlier_fraction = 0.0;
  o.drop_fraction = 0.0;
  return o;
}

}  // namespace

TEST(SimCellRangeSimulator, TagsRangeTheirNeighbourhoodAtTheScheduledRateAndNothingFarther) {
  // v0 in cell 0, v1 in cell 1 (its neighbour), v2 in cell 24 (far away).
  const World w({{-16, -16, 2}, {-10, -16, 3}, {16, 16, 5}});
  ASSERT_EQ(w.layout.cells().cellOf({-16, -16, 2}), 0);
  ASSERT_EQ(w.layout.cells().cellOf({-10, -16, 3}), 1);
  const CellRanges r = w.simulate(exact());
  const auto near0 = w.layout.anchorsNear(0);
  std::set<SensorId> heard;
  int to_v1 = 0;
  for (const SimulatedRange& x : r.vehicle[0]) {
    const SensorId b = x.sample.id_responder;
    EXPECT_TRUE(x.sample.id_initiator == 100 || x.sample.id_initiator == 105);
    if (w.isTag(b)) {
      EXPECT_EQ(b / 1000, 1) << "v0 ranged to a tag " << b << " outside its neighbourhood";
      ++to_v1;
      continue;
    }
    EXPECT_TRUE(std::binary_search(near0.begin(), near0.end(), b)) << "anchor " << b << " is not near cell 0";
    heard.insert(b);
    // No noise, no outliers: z = beta d + gamma exactly.
    const meshnav::PairBias& bias = w.biases->truth(x.sample.id_initiator, b);
    EXPECT_NEAR(x.sample.range_m, bias.beta * x.true_distance_m + bias.gamma_m, 1e-9);
  }
  EXPECT_EQ(heard.size(), near0.size()) << "the round robin covers every anchor of the neighbourhood";
  EXPECT_GT(to_v1, 0);
  // Two tags, one seat each: 2 x 4 ranges per 0.36 s frame.
  EXPECT_NEAR(static_cast<double>(r.vehicle[0].size()) / 20.0, 2 * 4 / 0.36, 1.0);
  EXPECT_EQ(r.stats[0].ranges, static_cast<int64_t>(r.vehicle[0].size()));
  EXPECT_EQ(r.stats[0].tag_to_tag, to_v1);
  EXPECT_EQ(r.stats[0].seat_waits, 0);
  for (const SimulatedRange& x : r.vehicle[2]) EXPECT_FALSE(w.isTag(x.sample.id_responder)) << "v2 has no neighbour";
  // The mesh: anchors of neighbouring cells only, every anchor initiating at 1 / 0.36 s.
  std::map<SensorId, int> initiated;
  for (const SimulatedRange& x : r.mesh) {
    EXPECT_TRUE(w.layout.cells().neighbours(w.layout.cellOfAnchor(x.sample.id_initiator),
                                            w.layout.cellOfAnchor(x.sample.id_responder)));
    ++initiated[x.sample.id_initiator];
  }
  EXPECT_EQ(initiated.size(), 100u);
  for (const auto& [id, n] : initiated) EXPECT_NEAR(n / 20.0, 1.0 / 0.36, 0.1) << id;
  // Time order within each list, and the same draws again give the same ranges.
  for (const auto& list : r.vehicle)
    EXPECT_TRUE(std::is_sorted(list.begin(), list.end(), [](const SimulatedRange& a, const SimulatedRange& b) {
      return a.sample.t < b.sample.t;
    }));
  const CellRanges again = w.simulate(exact());
  ASSERT_EQ(again.vehicle[1].size(), r.vehicle[1].size());
  for (size_t i = 0; i < r.vehicle[1].size(); ++i) EXPECT_EQ(again.vehicle[1][i].sample.range_m, r.vehicle[1][i].sample.range_m);
}

TEST(SimCellRangeSimulator, AnOutageSilencesTheAnchorsForOneVehicleButNotItsNeighbours) {
  const World w({{-16, -16, 2}, {-10, -16, 3}});
  CellOutage outage;
  outage.vehicle = 0;
  outage.t0_s = 5.0;
  outage.t1_s = 10.0;
  const CellRanges with = w.simulate(exact(), outage), without = w.simulate(exact());
  int anchors_in = 0, peers_in = 0;
  for (const SimulatedRange& x : with.vehicle[0]) {
    const double t = x.sample.t.sec();
    if (t < 5.0 || t > 10.0) continue;
    (w.isTag(x.sample.id_responder) ? peers_in : anchors_in)++;
  }
  EXPECT_EQ(anchors_in, 0);
  EXPECT_GT(peers_in, 10);
  // 5 s x 2 tags x 11.1 Hz, 16 of the 18 devices in its round robin are anchors.
  EXPECT_NEAR(static_cast<double>(with.stats[0].outage_silent), 5.0 * 2 * 4 / 0.36 * 16 / 18, 6.0);
  EXPECT_EQ(with.vehicle[1].size(), without.vehicle[1].size());  // v1 untouched
  EXPECT_EQ(with.mesh.size(), without.mesh.size());
}

TEST(SimCellRangeSimulator, WithAPeerPhaseTagsRangeEveryOtherVehicleAcrossTheHallAndNoPeerInTheCells) {
  // v0 in cell 0, v1 beside it, v2 in the far corner (no cell neighbour of either); v0 without
  // anchors over 5-10 s.
  const World w({{-16, -16, 2}, {-10, -16, 3}, {16, 16, 5}});
  CellOutage outage;
  outage.vehicle = 0;
  outage.t0_s = 5.0;
  outage.t1_s = 10.0;
  const CellRanges r = w.simulate(exact(), outage, {}, true);
  const CellRanges legacy = w.simulate(exact(), outage);
  // Frame: 180 + 6 peer slots = 0.372 s; each tag initiates one peer range per frame, in turn to
  // the four tags of the two other vehicles.
  const double frame_s = 186 * 0.002;
  for (size_t v = 0; v < 3; ++v) {
    std::map<SensorId, int> to_peer;
    int to_anchor = 0;
    for (const SimulatedRange& x : r.vehicle[v]) {
      if (!w.isTag(x.sample.id_responder)) {
        ++to_anchor;
        continue;
      }
      EXPECT_NE(x.sample.id_responder / 1000, static_cast<SensorId>(v));
      ++to_peer[x.sample.id_responder];
      // Exact: z = beta d + gamma between the two tags' true positions.
      const meshnav::PairBias& bias = w.biases->truth(x.sample.id_initiator, x.sample.id_responder);
      EXPECT_NEAR(x.sample.range_m, bias.beta * x.true_distance_m + bias.gamma_m, 1e-9);
    }
    EXPECT_EQ(to_peer.size(), 4u) << "v" << v << " ranges every tag of both other vehicles";
    int n_peer = 0;
    for (const auto& [id, n] : to_peer) n_peer += n;
    EXPECT_NEAR(n_peer / 20.0, 2.0 / frame_s, 0.2) << v;  // 2 tags x 1 slot per frame
    EXPECT_EQ(r.stats[v].tag_to_tag, n_peer);
    EXPECT_EQ(r.stats[v].peer_slots, n_peer);
    if (v > 0) EXPECT_NEAR(to_anchor / 20.0, 2 * 4 / frame_s, 1.0) << v;  // the cells: anchors only
  }
  // The outage silences v0's anchors, not its peers: 5 s x 2 / 0.372 s ≈ 27 peer ranges in it.
  int peers_in = 0;
  for (const SimulatedRange& x : r.vehicle[0])
    if (x.sample.t.sec() >= 5.0 && x.sample.t.sec() <= 10.0) {
      EXPECT_TRUE(w.isTag(x.sample.id_responder));
      ++peers_in;
    }
  EXPECT_NEAR(peers_in, 5.0 * 2 / frame_s, 2.0);
  // Without the peer phase v2, alone in its corner, never ranged a tag.
  for (const SimulatedRange& x : legacy.vehicle[2]) EXPECT_FALSE(w.isTag(x.sample.id_responder));
  // A schedule whose peer phase is not for this fleet's tags is refused.
  const CellTdmaSchedule wrong(w.layout.cells().colourCount(), {}, 0.0, 5);
  EXPECT_THROW(CellRangeSimulator(w.layout, w.vehicles, *w.biases, exact(), wrong, 7).simulate(1.0), std::invalid_argument);
}

TEST(SimCellRangeSimulator, ATagBeyondTheCellsSeatsWaits) {
  // Three vehicles (six tags) in cell 0, four seats: the two highest tag ids wait every phase.
  const World w({{-17, -17, 2}, {-16, -15, 3}, {-15, -17, 4}});
  const CellRanges r = w.simulate(exact());
  EXPECT_EQ(r.stats[0].seat_waits, 0);
  EXPECT_EQ(r.stats[1].seat_waits, 0);
  EXPECT_GT(r.stats[2].seat_waits, 50);
  EXPECT_TRUE(r.vehicle[2].empty());
}

TEST(SimCellRangeSimulator, RefusesACellWithMoreAnchorsThanSeats) {
  const World w({{0, 0, 2}});
  CellTdmaOptions tdma;
  tdma.anchor_seats = 3;
  EXPECT_THROW(w.simulate(exact(), {}, tdma), std::invalid_argument);
}
