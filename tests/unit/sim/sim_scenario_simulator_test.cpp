#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>

#include "common/dataset.h"
#include "sim/scenario_simulator.h"
#include "tests/support/test_util.h"

using namespace meshnav::sim;
namespace fs = std::filesystem;

namespace {
SimulationResult simulate(uint64_t seed, double scale = 1.0) {
  SimulationOptions o;
  o.seed = seed;
  o.duration_scale = scale;
  return ScenarioSimulator(o).run();
}

bool sameDataset(const meshnav::Dataset& a, const meshnav::Dataset& b) {
  if (a.imu.size() != b.imu.size() || a.ranges.size() != b.ranges.size() || a.baro.size() != b.baro.size() ||
      a.ground_truth.size() != b.ground_truth.size())
    return false;
  for (size_t k = 0; k < a.imu.size(); ++k)
    if (a.imu[k].t != b.imu[k].t || a.imu[k].acc_m_s2 != b.imu[k].acc_m_s2 || a.imu[k].gyro_rad_s != b.imu[k].gyro_rad_s)
      return false;
  for (size_t k = 0; k < a.ranges.size(); ++k)
    if (a.ranges[k].t != b.ranges[k].t || a.ranges[k].range_m != b.ranges[k].range_m ||
        a.ranges[k].id_initiator != b.ranges[k].id_initiator || a.ranges[k].id_responder != b.ranges[k].id_responder)
      return false;
  for (size_t k = 0; k < a.baro.size(); ++k)
    if (a.baro[k].pressure_pa != b.baro[k].pressure_pa) return false;
  for (size_t k = 0; k < a.ground_truth.size(); ++k)
    if (a.ground_truth[k].p_IinG != b.ground_truth[k].p_IinG) return false;
  return a.setup.initial_pose->p_IinG == b.setup.initial_pose->p_IinG;
}

std::string readFile(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
}  // namespace

TEST(SimScenarioSimulator, SameSeedGivesIdenticalDatasetDifferentSeedsDiffer) {
  const auto a = simulate(1), b = simulate(1), c = simulate(2);
  EXPECT_TRUE(sameDataset(a.dataset, b.dataset));
  EXPECT_FALSE(sameDataset(a.dataset, c.dataset));
  // And identical files on disk.
  const meshnav::test::TempDir dir("sim_test");
  meshnav::writeDataset(a.dataset, (dir / "a").string());
  meshnav::writeDataset(b.dataset, (dir / "b").string());
  for (const char* f : {"imu.csv", "baro.csv", "ranges.csv", "flight_state.csv", "groundtruth.csv", "setup.yaml", "truth.yaml"})
    EXPECT_EQ(readFile(dir / "a" / f), readFile(dir / "b" / f)) << f;
}

TEST(SimScenarioSimulator, RatesCountsAndFlightStates) {
  const auto r = simulate(5);
  const auto& ds = r.dataset;
  const double T = r.stats.duration_s;
  EXPECT_NEAR(ds.imu.size() / T, 200.0, 0.5);
  EXPECT_NEAR(ds.baro.size() / T, 50.0, 0.5);
  EXPECT_NEAR(ds.ground_truth.size() / T, 60.0, 0.5);
  EXPECT_NEAR(ds.flight_states.size() / T, 10.0, 0.5);
  EXPECT_NEAR(static_cast<double>(r.stats.n_range_slots) / T, 100.0, 0.5);  // one slot every 10 ms
  EXPECT_EQ(ds.ranges.size(), r.ranges.size());
  EXPECT_EQ(static_cast<int64_t>(ds.ranges.size()), r.stats.n_range_slots - r.stats.n_dropped);
  EXPECT_GT(r.stats.max_height_m, 7.5);
  // Landed on the pad at start and end, flying in between.
  EXPECT_TRUE(ds.flight_states.front().landed);
  EXPECT_TRUE(ds.flight_states.back().landed);
  EXPECT_TRUE(ds.flight_states[40].landed);  // 4 s
  EXPECT_FALSE(ds.flight_states[ds.flight_states.size() / 2].landed);
  int transitions = 0;
  for (size_t k = 1; k < ds.flight_states.size(); ++k) transitions += ds.flight_states[k].landed != ds.flight_states[k - 1].landed;
  EXPECT_EQ(transitions, 2);
  // Ranges are time ordered and stamped on the 10 ms TDMA grid.
  for (size_t k = 1; k < ds.ranges.size(); ++k) {
    ASSERT_GT(ds.ranges[k].t, ds.ranges[k - 1].t);
    EXPECT_EQ((ds.ranges[k].t - ds.ranges[0].t).us % 10000, 0);
  }
}

TEST(SimScenarioSimulator, SetupHoldsOnlyWhatAUserKnowsAndTruthEverything) {
  const auto r = simulate(3);
  const auto& setup = r.dataset.setup;
  EXPECT_EQ(setup.imu_id, 1);
  EXPECT_EQ(setup.baro_id, 2);
  EXPECT_EQ(setup.rel_tag_positions.size(), 2u);
  ASSERT_EQ(setup.abs_anchor_positions.size(), 4u);
  for (int id : {101, 102, 103, 104}) EXPECT_TRUE(setup.isKnownAnchor(id));
  EXPECT_FALSE(setup.isKnownAnchor(106));
  EXPECT_EQ(setup.pair_biases.size(), 15u);  // 6 devices choose 2
  EXPECT_FALSE(setup.findPairBias(100, 106).has_value());
  EXPECT_FALSE(setup.baro_reference_pressure_pa.has_value());
  EXPECT_EQ(setup.baro_p_IP, Eigen::Vector3d(0, 0, 0.05));
  ASSERT_TRUE(setup.initial_pose.has_value());
  const auto& gt0 = r.dataset.ground_truth.front();
  EXPECT_LT((setup.initial_pose->p_IinG - gt0.p_IinG).norm(), 0.3);
  ASSERT_TRUE(setup.noise.sigma_range_m.has_value());
  EXPECT_EQ(*setup.noise.sigma_range_m, 0.1);
  EXPECT_FALSE(setup.flight_volume.has_value());  // the paper scenario's files stay as they were

  ASSERT_TRUE(r.dataset.truth.has_value());
  const auto& truth = *r.dataset.truth;
  EXPECT_EQ(truth.anchor_positions.size(), 9u);
  EXPECT_EQ(truth.pair_biases.size(), 55u);
  EXPECT_EQ(truth.scalars.at("seed"), 3.0);
  EXPECT_NEAR(truth.scalars.at("baro_reference_pressure_pa"), 97000.0, 500.0);
  EXPECT_EQ(truth.scalars.at("n_outliers"), static_cast<double>(r.stats.n_outliers));
  // The a-priori γ is close to the true one (calibration error σ 0.02 m).
  for (const auto& pb : setup.pair_biases) {
    for (const auto& tb : truth.pair_biases)
      if (tb.a == pb.a && tb.b == pb.b) {
        EXPECT_LT(std::abs(tb.gamma_m - pb.gamma_m), 0.1);
      }
  }
}

TEST(SimScenarioSimulator, WrittenDatasetReadsBackCleanly) {
  SimulationOptions o;
  o.seed = 7;
  o.duration_scale = 0.3;
  o.with_initial_pose = false;
  const auto r = ScenarioSimulator(o).run();
  const meshnav::test::TempDir dir("sim_rt");
  meshnav::writeDataset(r.dataset, dir.string());
  meshnav::Diagnostics diag;
  const auto back = meshnav::readDataset(dir.string(), diag, true);
  EXPECT_EQ(diag.total(), 0) << diag.summary();
  EXPECT_EQ(back.imu.size(), r.dataset.imu.size());
  EXPECT_EQ(back.baro.size(), r.dataset.baro.size());
  EXPECT_EQ(back.ranges.size(), r.dataset.ranges.size());
  EXPECT_EQ(back.flight_states.size(), r.dataset.flight_states.size());
  EXPECT_EQ(back.ground_truth.size(), r.dataset.ground_truth.size());
  EXPECT_FALSE(back.setup.initial_pose.has_value());
  EXPECT_EQ(back.setup.pair_biases.size(), 15u);
  ASSERT_TRUE(back.truth.has_value());
  EXPECT_EQ(back.truth->anchor_positions.size(), 9u);
  EXPECT_NEAR(back.ranges[5].range_m, r.dataset.ranges[5].range_m, 1e-6);
  EXPECT_LT((back.ground_truth[100].p_IinG - r.dataset.ground_truth[100].p_IinG).norm(), 1e-6);
}

TEST(SimScenarioSimulator, RejectsInvalidOptions) {
  SimulationOptions o;
  o.uwb.outlier_fraction = 1.5;
  EXPECT_THROW(ScenarioSimulator{o}, std::invalid_argument);
  o = SimulationOptions{};
  o.uwb.sigma_range_m = -0.1;
  EXPECT_THROW(ScenarioSimulator{o}, std::invalid_argument);
}

namespace {
SimulationOptions generated(TrajectoryKind kind, uint64_t seed = 4) {
  SimulationOptions o;
  o.seed = seed;
  o.trajectory_kind = kind;
  o.hall_size_m = Eigen::Vector3d(10.0, 8.0, 4.0);
  o.anchor_layout = AnchorLayoutKind::Walls;
  o.n_tags = 3;
  o.n_known_anchors = 5;
  o.n_unknown_anchors = 3;
  o.duration_s = 40.0;
  return o;
}
}  // namespace

TEST(SimScenarioSimulator, WalkWritesNoBaroNoFlightStateNoInitialPoseAndReadsBack) {
  const auto r = ScenarioSimulator(generated(TrajectoryKind::Walk)).run();
  const auto& ds = r.dataset;
  EXPECT_TRUE(ds.baro.empty());
  EXPECT_TRUE(ds.flight_states.empty());
  EXPECT_FALSE(ds.setup.initial_pose.has_value());
  EXPECT_FALSE(r.has_landed_phase);
  const meshnav::test::TempDir dir("sim_walk");
  meshnav::writeDataset(ds, dir.string());
  EXPECT_FALSE(fs::exists(dir / "baro.csv"));
  EXPECT_FALSE(fs::exists(dir / "flight_state.csv"));
  meshnav::Diagnostics diag;
  const auto back = meshnav::readDataset(dir.string(), diag, true);
  EXPECT_EQ(diag.total(), 0) << diag.summary();
  EXPECT_TRUE(back.baro.empty());
  EXPECT_TRUE(back.flight_states.empty());
  EXPECT_EQ(back.imu.size(), ds.imu.size());
  EXPECT_EQ(back.ranges.size(), ds.ranges.size());
}

TEST(SimScenarioSimulator, GeneratedScenarioHasTheRequestedDevicesInTheTdma) {
  const auto r = ScenarioSimulator(generated(TrajectoryKind::Figure8)).run();
  const auto& ds = r.dataset;
  EXPECT_EQ(ds.setup.rel_tag_positions.size(), 3u);
  EXPECT_EQ(ds.setup.abs_anchor_positions.size(), 5u);
  EXPECT_EQ(ds.truth->anchor_positions.size(), 8u);
  EXPECT_EQ(ds.setup.pair_biases.size(), 28u);  // 8 tags and known anchors choose 2
  EXPECT_EQ(ds.truth->pair_biases.size(), 55u);  // 11 devices choose 2
  std::set<std::pair<meshnav::SensorId, meshnav::SensorId>> pairs;
  for (const auto& range : ds.ranges) pairs.insert({range.id_initiator, range.id_responder});
  EXPECT_EQ(pairs.size(), 110u);  // every ordered pair of the 11 devices is ranged
  EXPECT_TRUE(ds.setup.initial_pose.has_value());
  EXPECT_FALSE(ds.baro.empty());
  EXPECT_FALSE(ds.flight_states.empty());
  EXPECT_EQ(ds.truth->scalars.at("scenario_n_tags"), 3.0);
  // The user knows the hall: it is the flight volume, and every true position is inside it.
  ASSERT_TRUE(ds.setup.flight_volume.has_value());
  const Hall hall = generated(TrajectoryKind::Figure8).hall();
  EXPECT_EQ(ds.setup.flight_volume->min_m, hall.min_m);
  EXPECT_EQ(ds.setup.flight_volume->max_m, hall.max_m);
  for (const auto& g : ds.ground_truth) ASSERT_EQ(ds.setup.flight_volume->distanceOutside(g.p_IinG), 0.0);
}

TEST(SimScenarioSimulator, HoverStartsInTheAirWithAGivenBaroReference) {
  const auto r = ScenarioSimulator(generated(TrajectoryKind::Hover)).run();
  const auto& ds = r.dataset;
  EXPECT_TRUE(ds.flight_states.empty());
  EXPECT_FALSE(ds.setup.initial_pose.has_value());
  ASSERT_TRUE(ds.setup.baro_reference_pressure_pa.has_value());
  EXPECT_EQ(*ds.setup.baro_reference_pressure_pa, ds.truth->scalars.at("baro_reference_pressure_pa"));
  EXPECT_GT(ds.ground_truth.front().p_IinG.z(), 1.0);
}

TEST(SimScenarioSimulator, ImuGradeIsWrittenToTheSetup) {
  SimulationOptions o = generated(TrajectoryKind::Helix);
  o.imu = ImuNoiseOptions::forGrade("tactical");
  const auto r = ScenarioSimulator(o).run();
  EXPECT_EQ(*r.dataset.setup.noise.imu_acc_noise_density, 5e-4);
  EXPECT_EQ(*r.dataset.setup.noise.imu_gyro_bias_rw, 1e-6);
  EXPECT_THROW(ImuNoiseOptions::forGrade("navigation"), std::invalid_argument);
  EXPECT_EQ(ImuNoiseOptions::forGrade("fc").acc_noise_density, ImuNoiseOptions{}.acc_noise_density);
}

TEST(SimScenarioSimulator, RejectsBadScenarioOptions) {
  SimulationOptions o;
  o.n_tags = 0;
  EXPECT_THROW(ScenarioSimulator{o}, std::invalid_argument);
  o = SimulationOptions{};
  o.n_known_anchors = 6;
  EXPECT_THROW(ScenarioSimulator{o}, std::invalid_argument);
  o = SimulationOptions{};
  o.n_unknown_anchors = 6;  // paper layout: 4 + 6 > 9
  EXPECT_THROW(ScenarioSimulator{o}, std::invalid_argument);
  o = SimulationOptions{};
  o.hall_size_m = Eigen::Vector3d(2.0, 8.0, 4.0);
  EXPECT_THROW(ScenarioSimulator{o}, std::invalid_argument);
  o = SimulationOptions{};
  o.duration_s = 10.0;
  EXPECT_THROW(ScenarioSimulator{o}, std::invalid_argument);
}
