// Fly-by calibration through the in-process pipeline on simulated paper sequence 1 (scenario S2):
// known anchors 101–104, anchors 106/107 calibrated at 80 s and 108–110 at 100 s, then fused.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "common/pose_interpolation.h"
#include "pipeline/pipeline.h"
#include "sim/scenario_simulator.h"

using namespace meshnav;

namespace {

struct Flight {
  Dataset ds;
  std::vector<estimator::EstimatorInput> inputs;
};

const Flight& flight1() {
  static const Flight f = [] {
    sim::SimulationOptions o;
    o.seed = 1;
    Flight fl;
    fl.ds = sim::ScenarioSimulator(o).run().dataset;
    fl.inputs = estimator::mergeInTimeOrder(fl.ds);
    return fl;
  }();
  return f;
}

struct RunResult {
  std::vector<PoseEstimate> poses, smoothed;
  std::vector<AnchorInit> inits;
  std::map<SensorId, AnchorEstimate> final_anchors;
  EstimatorStatus status;
};

RunResult runPipeline(const Flight& f, bool with_mission, bool calibrate_on_smoothed = false) {
  pipeline::PipelineOptions o;
  o.calibrator_on_smoothed = calibrate_on_smoothed;
  if (with_mission) o.mission = mission::loadMission(std::string(MESHNAV_SOURCE_DIR) + "/config/missions/paper_s2.yaml");
  RunResult r;
  pipeline::PipelineSinks sinks;
  sinks.pose = [&](size_t, const PoseEstimate& p) { r.poses.push_back(p); };
  sinks.pose_smoothed = [&](size_t, const PoseEstimate& p) { r.smoothed.push_back(p); };
  sinks.anchor_init = [&](const AnchorInit& a) { r.inits.push_back(a); };
  pipeline::Pipeline p(o, f.ds.setup, sinks);
  for (const auto& in : f.inputs) p.onInput(in);
  p.finish();
  for (const auto& a : p.estimator().anchors()) r.final_anchors[a.id] = a;
  r.status = p.estimator().status();
  return r;
}

double positionRmse(const std::vector<PoseEstimate>& est, const std::vector<PoseSample>& gt) {
  double sq = 0;
  int n = 0;
  for (const auto& e : est) {
    auto g = interpolatePose(gt, e.t);
    if (!g) continue;
    sq += (e.p_IinG - g->p_IinG).squaredNorm();
    ++n;
  }
  return n ? std::sqrt(sq / n) : 1e9;
}

}  // namespace

TEST(Pipeline, FlyByCalibrationWithTheS2Mission) {
  const Flight& f = flight1();
  ASSERT_TRUE(f.ds.truth);
  const RunResult r = runPipeline(f, true);
  // Five anchors initialized, at the mission's times, each with biases towards both tags.
  ASSERT_EQ(r.inits.size(), 5u);
  std::map<SensorId, double> init_err;
  for (const auto& a : r.inits) {
    const double t_rel = (a.t - estimator::inputTime(f.inputs.front())).sec();
    if (a.id == 106 || a.id == 107) EXPECT_NEAR(t_rel, 80.0, 1.0) << a.id;
    else EXPECT_NEAR(t_rel, 100.0, 1.0) << a.id;
    init_err[a.id] = (a.p_AinG - f.ds.truth->anchor_positions.at(a.id)).norm();
    const Eigen::Vector3d e = a.p_AinG - f.ds.truth->anchor_positions.at(a.id);
    const double nees = e.dot(a.cov_p_m2.inverse() * e);
    std::cout << "anchor " << a.id << ": initial NEES " << nees << "\n";
    // Consistent initial belief: within the 99.7 % bound of χ²(3) although the tag poses are
    // estimated (their errors are correlated over the collection window).
    EXPECT_LT(nees, 13.93) << a.id;
    EXPECT_LT(init_err[a.id], 0.30) << "initial belief of " << a.id;
    int tag_refs = 0;
    for (const auto& b : a.biases) tag_refs += (b.a == 100 || b.a == 105 || b.b == 100 || b.b == 105);
    EXPECT_EQ(tag_refs, 2) << a.id;
  }
  // The estimator created the instances and refined them.
  for (SensorId id : {106, 107, 108, 109, 110}) {
    ASSERT_TRUE(r.final_anchors.count(id)) << id;
    const double err = (r.final_anchors.at(id).p_AinG - f.ds.truth->anchor_positions.at(id)).norm();
    EXPECT_LT(err, 0.30) << "final estimate of " << id;
    std::cout << "anchor " << id << ": initial error " << init_err[id] << " m, final error " << err << " m\n";
    const auto it = std::find_if(r.status.instances.begin(), r.status.instances.end(),
                                 [&](const InstanceStatus& s) { return s.id == id; });
    ASSERT_NE(it, r.status.instances.end()) << id;
    EXPECT_GT(it->n_updates, 20) << "ranges of " << id << " were fused";
  }
  // Every instance is listed once in ESTIMATOR_STATUS (tags with estimated biases included).
  std::map<SensorId, int> listed;
  for (const auto& i : r.status.instances) ++listed[i.id];
  for (const auto& [id, n] : listed) EXPECT_EQ(n, 1) << "instance " << id << " listed " << n << " times";
  EXPECT_EQ(listed.size(), 1u + 1u + 2u + 9u);  // IMU, baro, tags 100/105, anchors 101–110
  const double rmse = positionRmse(r.poses, f.ds.ground_truth);
  std::cout << "position RMSE " << rmse << " m over " << r.poses.size() << " poses\n";
  EXPECT_LE(rmse, 0.15);
}

TEST(Pipeline, WithoutMissionNewAnchorsAreCalibratedAutomatically) {
  const RunResult r = runPipeline(flight1(), false);
  std::set<SensorId> ids;
  for (const auto& a : r.inits) ids.insert(a.id);
  EXPECT_EQ(ids, (std::set<SensorId>{106, 107, 108, 109, 110}));
  for (const auto& a : r.inits) EXPECT_LT((a.p_AinG - flight1().ds.truth->anchor_positions.at(a.id)).norm(), 0.30);
}

TEST(Pipeline, IsDeterministic) {
  const RunResult a = runPipeline(flight1(), true);
  const RunResult b = runPipeline(flight1(), true);
  ASSERT_EQ(a.poses.size(), b.poses.size());
  EXPECT_EQ(a.poses.back().p_IinG, b.poses.back().p_IinG);
  ASSERT_EQ(a.inits.size(), b.inits.size());
  for (size_t i = 0; i < a.inits.size(); ++i) EXPECT_EQ(a.inits[i].p_AinG, b.inits[i].p_AinG);
}

// The fixed-lag smoother through the pipeline (issue 35): one smoothed pose per POSE at its time,
// closer to the truth; with calibrator_on_smoothed the calibrator takes them instead of the
// filter's (its calibrations change) and still calibrates every fly-by anchor.
TEST(Pipeline, FixedLagSmoothedPosesAndTheCalibratorOnThem) {
  const RunResult r = runPipeline(flight1(), true);
  ASSERT_EQ(r.smoothed.size(), r.poses.size());
  for (size_t i = 0; i < r.poses.size(); ++i) ASSERT_EQ(r.smoothed[i].t, r.poses[i].t);
  const auto& gt = flight1().ds.ground_truth;
  EXPECT_LT(positionRmse(r.smoothed, gt), 0.8 * positionRmse(r.poses, gt));

  const RunResult s = runPipeline(flight1(), true, true);
  ASSERT_EQ(s.inits.size(), r.inits.size());
  double moved = 0.0;
  for (size_t i = 0; i < s.inits.size(); ++i) {
    ASSERT_EQ(s.inits[i].id, r.inits[i].id);
    moved = std::max(moved, (s.inits[i].p_AinG - r.inits[i].p_AinG).norm());
    EXPECT_LT((s.inits[i].p_AinG - flight1().ds.truth->anchor_positions.at(s.inits[i].id)).norm(), 0.30);
  }
  EXPECT_GT(moved, 1e-4);  // the calibrator did take the smoothed poses
}
