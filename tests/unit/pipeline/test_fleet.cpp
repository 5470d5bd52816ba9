// Several vehicles sharing one anchor map (pipeline/fleet.h, docs/fleet.md): the fleet file, the
// merged setups, ANCHOR_INITs restricted per vehicle, the merged input order, and a simulated
// two-vehicle fleet through the pipeline against each vehicle alone.
#include <gtest/gtest.h>

#include <limits>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "common/pose_interpolation.h"
#include "pipeline/fleet.h"
#include "pipeline/pipeline.h"
#include "sim/fleet_simulation.h"
#include "tests/support/test_util.h"

using namespace meshnav;
using namespace meshnav::pipeline;

namespace {

/// Writes `text` to a fresh file in this test program's temporary folder (removed at exit); returns its path.
std::string writeFile(const std::string& name, const std::string& text) {
  static const meshnav::test::TempDir dir("test_fleet");
  const auto path = dir / name;
  std::ofstream(path) << text;
  return path.string();
}

/// The message of the std::exception `f` throws ("" if none).
template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

SystemSetup vehicleSetup(std::map<SensorId, Eigen::Vector3d> tags) {
  SystemSetup s;
  s.rel_tag_positions = std::move(tags);
  s.abs_anchor_positions = {{101, {0, 0, 2}}, {102, {4, 0, 2}}};
  return s;
}

}  // namespace

TEST(FleetFile, ReadsTheVehiclesAndResolvesDatasetsAgainstTheFilesFolder) {
  const std::string path = writeFile("ok.yaml",
                                     "vehicles:\n"
                                     "  - {name: ifo001, dataset: a/ifo001}\n"
                                     "  - name: ifo_2\n"
                                     "    dataset: /abs/ifo002\n");
  const auto v = loadFleetFile(path);
  ASSERT_EQ(v.size(), 2u);
  EXPECT_EQ(v[0].name, "ifo001");
  EXPECT_EQ(v[0].dataset, (std::filesystem::path(path).parent_path() / "a/ifo001").string());
  EXPECT_EQ(v[1].name, "ifo_2");
  EXPECT_EQ(v[1].dataset, "/abs/ifo002");
}

TEST(FleetFile, RefusesUnknownKeysMissingKeysBadAndRepeatedNamesNamingFileAndKey) {
  struct Case {
    std::string text, expect;
  };
  const std::vector<Case> cases = {
      {"vehicles:\n  - {name: a, dataset: a, config: x}\n", "unknown key 'vehicles[0].config'"},
      {"vehicle:\n  - {name: a, dataset: a}\n", "unknown key 'vehicle'"},
      {"vehicles:\n  - {dataset: a}\n", "vehicles[0].name"},
      {"vehicles:\n  - {name: a}\n", "vehicles[0].dataset"},
      {"vehicles: []\n", "'vehicles' must be a non-empty list"},
      {"{}\n", "'vehicles' is missing"},
      {"vehicles:\n  - {name: 'a b', dataset: a}\n", "letters, digits"},
      {"vehicles:\n  - {name: ../up, dataset: a}\n", "letters, digits"},
      {"vehicles:\n  - {name: a, dataset: a}\n  - {name: a, dataset: b}\n", "'vehicles[1].name' 'a' is the name of an earlier vehicle"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const std::string path = writeFile("bad" + std::to_string(i) + ".yaml", cases[i].text);
    const std::string msg = errorOf([&] { loadFleetFile(path); });
    EXPECT_NE(msg.find(path), std::string::npos) << "case " << i << ": " << msg;
    EXPECT_NE(msg.find(cases[i].expect), std::string::npos) << "case " << i << ": " << msg;
  }
  EXPECT_NE(errorOf([] { loadFleetFile("/nonexistent/fleet.yaml"); }).find("cannot open"), std::string::npos);
}

TEST(FleetSetups, EveryVehicleGetsTheSharedMapAndConflictsAreRefused) {
  std::vector<Vehicle> v = {{"a", vehicleSetup({{10, {0.1, 0, 0}}})}, {"b", vehicleSetup({{20, {0, 0.1, 0}}})}};
  v[1].setup.abs_anchor_positions[103] = {0, 4, 2};   // only b knows 103
  v[0].setup.pair_biases.push_back({10, 101, 0.1});  // a's own tag pair
  v[1].setup.pair_biases.push_back({101, 102, 0.2}); // a mesh pair
  const SystemSetup fleet = mergeFleetSetups(v, "fleet.yaml");
  EXPECT_EQ(fleet.rel_tag_positions.size(), 2u);
  EXPECT_TRUE(fleet.isTag(10) && fleet.isTag(20));
  EXPECT_EQ(fleet.abs_anchor_positions.size(), 3u);
  EXPECT_EQ(fleet.pair_biases.size(), 2u);
  for (const Vehicle& x : v) {
    EXPECT_EQ(x.setup.abs_anchor_positions.size(), 3u) << x.name << " knows the whole map";
    EXPECT_EQ(x.setup.rel_tag_positions.size(), 1u) << x.name << " keeps its own tags only";
  }
  EXPECT_EQ(v[0].setup.pair_biases.size(), 2u);  // its tag pair and the mesh pair
  ASSERT_EQ(v[1].setup.pair_biases.size(), 1u);  // not a's tag pair
  EXPECT_EQ(v[1].setup.pair_biases[0].a, 101);

  auto refused = [](std::vector<Vehicle> w) { return errorOf([&] { mergeFleetSetups(w, "f.yaml"); }); };
  std::vector<Vehicle> same_tag = {{"a", vehicleSetup({{10, {0, 0, 0}}})}, {"b", vehicleSetup({{10, {0, 0, 0}}})}};
  EXPECT_NE(refused(same_tag).find("tag 10 of b is also a tag of a"), std::string::npos) << refused(same_tag);
  std::vector<Vehicle> moved = {{"a", vehicleSetup({{10, {0, 0, 0}}})}, {"b", vehicleSetup({{20, {0, 0, 0}}})}};
  moved[1].setup.abs_anchor_positions[102] = {4, 0.01, 2};
  EXPECT_NE(refused(moved).find("anchor 102 is at a different position in b than in a"), std::string::npos);
  std::vector<Vehicle> tag_is_anchor = {{"a", vehicleSetup({{10, {0, 0, 0}}})}, {"b", vehicleSetup({{102, {0, 0, 0}}})}};
  tag_is_anchor[1].setup.abs_anchor_positions.erase(102);
  EXPECT_NE(refused(tag_is_anchor).find("tag 102 of b is a known anchor"), std::string::npos) << refused(tag_is_anchor);
  std::vector<Vehicle> tag_is_imu = {{"a", vehicleSetup({{10, {0, 0, 0}}})}, {"b", vehicleSetup({{1, {0, 0, 0}}})}};
  EXPECT_NE(refused(tag_is_imu).find("IMU's or the baro's id of a"), std::string::npos) << refused(tag_is_imu);
  std::vector<Vehicle> pair = {{"a", vehicleSetup({{10, {0, 0, 0}}})}, {"b", vehicleSetup({{20, {0, 0, 0}}})}};
  pair[0].setup.pair_biases.push_back({101, 102, 0.2});
  pair[1].setup.pair_biases.push_back({102, 101, 0.3});
  EXPECT_NE(refused(pair).find("pair bias 101-102 of b differs from a's"), std::string::npos) << refused(pair);
  EXPECT_NE(refused({}).find("at least one vehicle"), std::string::npos);
}

TEST(FleetSetups, AnAnchorInitKeepsOnlyTheVehiclesOwnTagsWithTheirJointCovariance) {
  const SystemSetup a = vehicleSetup({{10, {0, 0, 0}}, {11, {0, 0, 0}}});
  const SystemSetup b = vehicleSetup({{20, {0, 0, 0}}});
  SystemSetup fleet = a;
  fleet.rel_tag_positions[20] = {0, 0, 0};
  AnchorInit init;
  init.id = 106;
  for (SensorId ref : {10, 20, 101, 11}) init.biases.push_back({ref, 106, 0.01 * ref, 1.0, 0.1, 0.2});
  init.cov_gamma_p_m2 = Eigen::MatrixXd(4, 3);
  init.cov_gamma_m2 = Eigen::MatrixXd(4, 4);
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 3; ++j) init.cov_gamma_p_m2(i, j) = 10 * i + j;
    for (int j = 0; j < 4; ++j) init.cov_gamma_m2(i, j) = 100 + 10 * i + j;
  }
  const AnchorInit ra = restrictToVehicle(init, a, fleet);  // drops 20 (index 1)
  ASSERT_EQ(ra.biases.size(), 3u);
  EXPECT_EQ(ra.biases[0].a, 10);
  EXPECT_EQ(ra.biases[1].a, 101);
  EXPECT_EQ(ra.biases[2].a, 11);
  EXPECT_TRUE(ra.jointCovarianceError().empty()) << ra.jointCovarianceError();
  const std::vector<int> kept = {0, 2, 3};
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(ra.cov_gamma_p_m2.row(i), init.cov_gamma_p_m2.row(kept[i]));
    for (int j = 0; j < 3; ++j) EXPECT_EQ(ra.cov_gamma_m2(i, j), init.cov_gamma_m2(kept[i], kept[j]));
  }
  const AnchorInit rb = restrictToVehicle(init, b, fleet);  // keeps 20 and the anchor 101
  ASSERT_EQ(rb.biases.size(), 2u);
  EXPECT_EQ(rb.biases[0].a, 20);
  EXPECT_EQ(rb.biases[1].a, 101);
  EXPECT_EQ(rb.cov_gamma_m2(1, 0), init.cov_gamma_m2(2, 1));
  // Nothing foreign: unchanged.
  const AnchorInit same = restrictToVehicle(init, fleet, fleet);
  EXPECT_EQ(same.biases.size(), 4u);
  EXPECT_EQ(same.cov_gamma_m2, init.cov_gamma_m2);
}

TEST(FleetInputs, OneTimeOrderWithTheLowerVehicleFirstOnEqualTimes) {
  auto imu = [](double t) { return estimator::EstimatorInput(ImuSample{Timestamp::fromSec(t)}); };
  auto range = [](double t) {
    RangeSample r;
    r.t = Timestamp::fromSec(t);
    return estimator::EstimatorInput(r);
  };
  const auto merged = mergeFleetInputs({{imu(1.0), range(1.0), imu(3.0)}, {imu(0.5), imu(1.0), imu(2.0)}});
  std::vector<std::pair<size_t, double>> got;
  for (const auto& f : merged) got.emplace_back(f.vehicle, estimator::inputTime(f.input).sec());
  const std::vector<std::pair<size_t, double>> want = {{1, 0.5}, {0, 1.0}, {0, 1.0}, {1, 1.0}, {1, 2.0}, {0, 3.0}};
  EXPECT_EQ(got, want);
  EXPECT_TRUE(std::holds_alternative<RangeSample>(merged[2].input)) << "a vehicle keeps its own order";
}

namespace {

struct VehicleResult {
  std::vector<PoseEstimate> poses;
  std::map<SensorId, AnchorEstimate> final_anchors;
  std::vector<AnchorInit> inits_received;  ///< as this vehicle's estimator got them
};

struct FleetResult {
  std::vector<VehicleResult> vehicles;
  std::vector<AnchorInit> inits;  ///< as the calibrator sent them
  std::map<SensorId, int> tag_inliers;  ///< per calibrated anchor: inlier ranges to tags (moving references)
  std::map<std::string, int64_t> pipeline_counters, calibrator_counters;
};

const std::vector<sim::SimulationResult>& simulatedFleet() {
  static const auto fleet = sim::simulateFleet(sim::SimulationOptions{}, 2);
  return fleet;
}

/// The S2 mission (106/107 at 80 s, 108–110 at 100 s) over the given datasets as one fleet.
FleetResult runFleet(const std::vector<const Dataset*>& datasets) {
  PipelineOptions o;
  o.mission = mission::loadMission(std::string(MESHNAV_SOURCE_DIR) + "/config/missions/paper_s2.yaml");
  std::vector<Vehicle> vehicles;
  for (size_t v = 0; v < datasets.size(); ++v) vehicles.push_back({"v" + std::to_string(v), datasets[v]->setup});
  const SystemSetup fleet_setup = mergeFleetSetups(vehicles, "test");
  FleetResult r;
  r.vehicles.resize(datasets.size());
  PipelineSinks sinks;
  sinks.pose = [&](size_t v, const PoseEstimate& p) { r.vehicles[v].poses.push_back(p); };
  sinks.anchor_init = [&](const AnchorInit& a) { r.inits.push_back(a); };
  Pipeline pipe(o, vehicles, fleet_setup, sinks);
  std::vector<std::vector<estimator::EstimatorInput>> per_vehicle;
  for (const Dataset* d : datasets) per_vehicle.push_back(estimator::mergeInTimeOrder(*d));
  for (const auto& [v, in] : mergeFleetInputs(per_vehicle)) pipe.onInput(v, in);
  for (size_t v = 0; v < datasets.size(); ++v)
    for (const auto& a : pipe.estimator(v).anchors()) r.vehicles[v].final_anchors[a.id] = a;
  for (const auto& res : pipe.calibrator()->results())
    for (const auto& ref : res.references)
      if (ref.moving) r.tag_inliers[res.anchor_id] += ref.n_inliers;
  r.pipeline_counters = pipe.diagnostics().snapshot();
  r.calibrator_counters = pipe.calibrator()->diagnostics().snapshot();
  return r;
}

double positionRmse(const std::vector<PoseEstimate>& est, const std::vector<PoseSample>& gt) {
  double sq = 0;
  int n = 0;
  for (const auto& e : est)
    if (const auto g = interpolatePose(gt, e.t)) {
      sq += (e.p_IinG - g->p_IinG).squaredNorm();
      ++n;
    }
  return n ? std::sqrt(sq / n) : 1e9;
}

double meanInitError(const std::vector<AnchorInit>& inits, const Truth& truth) {
  double s = 0;
  for (const auto& a : inits) s += (a.p_AinG - truth.anchor_positions.at(a.id)).norm();
  return inits.empty() ? 1e9 : s / static_cast<double>(inits.size());
}

}  // namespace

TEST(SimulatedFleet, IsOneWorldWithOneMeshAndItsOwnTagsPerVehicle) {
  const auto& f = simulatedFleet();
  ASSERT_EQ(f.size(), 2u);
  const Dataset &d0 = f[0].dataset, &d1 = f[1].dataset;
  ASSERT_TRUE(d0.truth && d1.truth);
  EXPECT_EQ(d0.truth->anchor_positions, d1.truth->anchor_positions);
  EXPECT_EQ(d0.setup.abs_anchor_positions, d1.setup.abs_anchor_positions);
  std::set<SensorId> tags1;
  for (const auto& [id, p] : d1.setup.rel_tag_positions) tags1.insert(id);
  EXPECT_EQ(tags1, (std::set<SensorId>{1100, 1105}));
  // The anchors' ranges up to `until` (µs).
  auto mesh = [](const Dataset& d, int64_t until) {
    std::vector<std::tuple<int64_t, SensorId, SensorId, double>> m;
    for (const auto& r : d.ranges)
      if (r.type_initiator == UwbType::Anchor && r.type_responder == UwbType::Anchor && r.t.us <= until)
        m.emplace_back(r.t.us, r.id_initiator, r.id_responder, r.range_m);
    return m;
  };
  const int64_t end1 = d1.imu.back().t.us, all = std::numeric_limits<int64_t>::max();
  EXPECT_GT(mesh(d0, all).size(), 1000u);
  // One mesh, heard by both: vehicle 1 has vehicle 0's, within its own recording (a range after its
  // last IMU sample is an input its estimate could never reach).
  EXPECT_EQ(mesh(d0, end1), mesh(d1, all)) << "one mesh, heard by both";
  for (const auto& r : d1.ranges) {
    if (r.type_initiator == UwbType::Tag) {
      ASSERT_TRUE(tags1.count(r.id_initiator)) << r.id_initiator;
    }
  }
  // Two flights, not one twice: the vehicles are apart most of the time.
  const auto g = interpolatePose(d1.ground_truth, d0.ground_truth[d0.ground_truth.size() / 2].t);
  ASSERT_TRUE(g.has_value());
  EXPECT_GT((g->p_IinG - d0.ground_truth[d0.ground_truth.size() / 2].p_IinG).norm(), 0.3);
}

TEST(FleetPipeline, OneCalibrationFromBothVehiclesReachesBothEstimators) {
  const auto& f = simulatedFleet();
  const Truth& truth = *f[0].dataset.truth;
  const FleetResult fleet = runFleet({&f[0].dataset, &f[1].dataset});
  const FleetResult alone = runFleet({&f[0].dataset});
  ASSERT_EQ(fleet.inits.size(), 5u);
  ASSERT_EQ(alone.inits.size(), 5u);
  for (size_t k = 0; k < fleet.inits.size(); ++k) {
    const AnchorInit& a = fleet.inits[k];
    std::set<SensorId> refs;
    for (const auto& b : a.biases) refs.insert(b.a == a.id ? b.b : b.a);
    for (SensorId tag : {100, 105, 1100, 1105}) EXPECT_TRUE(refs.count(tag)) << a.id << " has no bias for tag " << tag;
    // Both vehicles' tag ranges (the mesh ranges count once).
    EXPECT_GT(fleet.tag_inliers.at(a.id), 1.6 * alone.tag_inliers.at(a.id)) << a.id;
  }
  const double err_fleet = meanInitError(fleet.inits, truth), err_alone = meanInitError(alone.inits, truth);
  std::printf("calibration at the S2 times, mean error: fleet %.3f m, vehicle 0 alone %.3f m\n", err_fleet, err_alone);
  EXPECT_LT(err_fleet, 0.10);
  for (size_t v = 0; v < 2; ++v) {
    const VehicleResult& r = fleet.vehicles[v];
    const double rmse = positionRmse(r.poses, f[v].dataset.ground_truth);
    std::printf("vehicle %zu: position RMSE %.3f m\n", v, rmse);
    EXPECT_LT(rmse, 0.15) << v;
    for (SensorId id : {106, 107, 108, 109, 110}) {
      ASSERT_TRUE(r.final_anchors.count(id)) << "vehicle " << v << " fuses anchor " << id;
      EXPECT_LT((r.final_anchors.at(id).p_AinG - truth.anchor_positions.at(id)).norm(), 0.2) << v << ": " << id;
    }
  }
  // The mesh is in both datasets; the calibrator saw each of its ranges once, silently.
  EXPECT_GT(fleet.pipeline_counters.at("mesh_range_from_another_vehicle"), 1000);
  EXPECT_EQ(fleet.calibrator_counters.count("RANGE:duplicate"), 0u);
  EXPECT_EQ(fleet.calibrator_counters.count("ranges_evicted"), 0u);
  EXPECT_EQ(alone.pipeline_counters.count("mesh_range_from_another_vehicle"), 0u);
}

// A range between two vehicles' tags is counted per vehicle whose data carries it; logged by both
// it is used once (the second is a duplicate); with no estimate on either side it goes nowhere.
TEST(FleetPipeline, ARangeToAnotherVehiclesTagIsCountedAndUsedOnce) {
  std::vector<Vehicle> v = {{"a", vehicleSetup({{10, {0, 0, 0}}})}, {"b", vehicleSetup({{20, {0, 0, 0}}})}};
  const SystemSetup fleet = mergeFleetSetups(v, "test");
  Pipeline pipe(PipelineOptions{}, v, fleet);
  RangeSample r;
  r.t = Timestamp::fromSec(1.0);
  r.id_initiator = 10;
  r.id_responder = 20;
  r.type_responder = UwbType::Tag;
  r.range_m = r.range_corr_m = 2.0;
  pipe.onInput(0, r);
  pipe.onInput(1, r);
  EXPECT_EQ(pipe.diagnostics().get("inter_vehicle_range:a"), 1);
  EXPECT_EQ(pipe.diagnostics().get("inter_vehicle_range:b"), 1);
  EXPECT_EQ(pipe.diagnostics().get("inter_vehicle_range_duplicate"), 1);
  EXPECT_EQ(pipe.diagnostics().get("inter_vehicle_range_no_estimate"), 1);
  EXPECT_EQ(pipe.calibrator()->diagnostics().get("ranges_received"), 0);
  EXPECT_THROW(pipe.onInput(2, r), std::out_of_range);
  EXPECT_THROW(Pipeline(PipelineOptions{}, std::vector<Vehicle>{}, fleet), std::invalid_argument);
  std::vector<Vehicle> stranger = {{"c", vehicleSetup({{30, {0, 0, 0}}})}};
  EXPECT_THROW(Pipeline(PipelineOptions{}, stranger, fleet), std::invalid_argument);
}
