/// Restart checkpoint over the kind registry (issue 11): estimator_state.yaml layout 2 round trip,
/// malformed and old-layout files refused naming the file and key, and a restart that keeps the
/// kinds marked Restart::kKept (the height bias and the tags' γ, which restarted from their priors
/// before).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "estimator/restart/checkpoint.h"
#include "estimator/node/estimator_node.h"
#include "estimator/testing/synthetic_scenario.h"
#include "tests/support/test_util.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

/// The synthetic flight with a rangefinder 0.1 m below the IMU that reads a floor offset of
/// `bias` [m], and a-priori uncertain γ (σ 0.1 m, true 0) between the tags and anchors 101, 102.
Dataset heightFlight(double bias) {
  synthetic::SyntheticOptions o;
  o.duration_s = 20.0;
  Dataset ds = synthetic::makeSyntheticDataset(o);
  ds.setup.height_p_IH = Eigen::Vector3d(0.0, 0.0, -0.1);
  for (size_t i = 0; i < ds.ground_truth.size(); i += 7) {
    const PoseSample& g = ds.ground_truth[i];
    const Eigen::Matrix3d R = g.q_ItoG.toRotationMatrix();
    ds.heights.push_back({g.t, (g.p_IinG + R * ds.setup.height_p_IH).z() / R(2, 2) + bias});
  }
  for (SensorId tag : {100u, 105u})
    for (SensorId anchor : {101u, 102u}) {
      std::erase_if(ds.setup.pair_biases, [&](const PairBias& p) {
        return (p.a == tag && p.b == anchor) || (p.a == anchor && p.b == tag);
      });
      PairBias pb;
      pb.a = tag;
      pb.b = anchor;
      pb.sigma_gamma_m = 0.1;
      ds.setup.pair_biases.push_back(pb);
    }
  return ds;
}

/// Feeds `node` the inputs of `ds` (in their canonical order) from `after_s` to `until_s` [s].
void runUntil(EstimatorNode& node, const Dataset& ds, double until_s, double after_s = -1.0) {
  for (const auto& in : mergeInTimeOrder(ds)) {
    if (inputTime(in).sec() <= after_s) continue;
    if (inputTime(in).sec() > until_s) break;
    node.onInput(in);
  }
}

/// A fresh folder `name` in this binary's private temp folder (removed at exit).
std::string tempDir(const std::string& name) {
  static const meshnav::test::TempDir root("checkpoint");
  const std::string dir = (root / name).string();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

void writeText(const std::string& file, const std::string& text) {
  std::ofstream f(file);
  f << text;
}

/// The message readCheckpoint(dir) throws ("" when it accepts the folder).
std::string refusal(const std::string& dir) {
  try {
    readCheckpoint(dir);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

/// A valid IMU record: at rest at z = 1 m, identity covariance.
std::string imuRecord() {
  std::string cov;
  for (int i = 0; i < ImuErr::kDim * ImuErr::kDim; ++i)
    cov += std::string(i ? ", " : "") + (i % (ImuErr::kDim + 1) == 0 ? "1" : "0");
  return "  - kind: imu\n    id: 1\n    value: [0, 0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0]\n    cov: [" + cov + "]\n";
}
constexpr const char* kHeader = "format: meshnav_estimator_state\nversion: 2\nt: 1.0\nlanded: false\n"
                                "baro_reference_pa: null\ninstances:\n";

}  // namespace

TEST(Checkpoint, Layout2RoundTripsEveryKeptInstance) {
  const Dataset ds = heightFlight(0.25);
  EstimatorNode node(EstimatorOptions{}, ds.setup);
  runUntil(node, ds, 15.0);
  ASSERT_TRUE(node.initialized());
  const EstimatorCheckpoint c = node.checkpoint();
  // Every Restart::kKept kind of this setup is in it: baro 2, height, tags 100 and 105.
  ASSERT_NE(c.find("baro", ds.setup.baro_id), nullptr);
  ASSERT_NE(c.find("height", ds.setup.height_id), nullptr);
  ASSERT_NE(c.find("tag", 100), nullptr);
  ASSERT_NE(c.find("tag", 105), nullptr);
  EXPECT_EQ(c.find("tag", 100)->peers, (std::vector<SensorId>{101, 102}));
  const std::string dir = tempDir("meshnav_checkpoint_layout2");
  writeCheckpoint(c, dir);
  const auto back = readCheckpoint(dir);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->t, c.t);
  EXPECT_EQ(back->imu_id, c.imu_id);
  EXPECT_NEAR((back->imu.p_IinG - c.imu.p_IinG).norm(), 0.0, 1e-12);
  EXPECT_NEAR(back->imu.q_ItoG.angularDistance(c.imu.q_ItoG), 0.0, 1e-12);
  EXPECT_NEAR((back->cov_imu - c.cov_imu).norm(), 0.0, 1e-15);
  ASSERT_EQ(back->instances.size(), c.instances.size());
  for (size_t i = 0; i < c.instances.size(); ++i) {
    const InstanceRecord &a = c.instances[i], &b = back->instances[i];
    EXPECT_EQ(b.kind, a.kind);
    EXPECT_EQ(b.id, a.id);
    EXPECT_EQ(b.peers, a.peers);
    EXPECT_EQ(b.value, a.value) << a.kind << " " << a.id;  // 17 digits: exact
    EXPECT_EQ(b.cov, a.cov) << a.kind << " " << a.id;
  }
}

// The anchors' file is written only when asked (the process: every --anchors-period and when the
// set changes) or when there is none yet; the state file every time.
TEST(Checkpoint, TheAnchorsFileIsWrittenWhenAskedOrMissing) {
  EstimatorCheckpoint c;
  c.t = Timestamp::fromSec(1.0);
  AnchorInit a;
  a.id = 106;
  a.t = c.t;
  a.p_AinG = {1, 2, 3};
  a.cov_p_m2 = 0.01 * Eigen::Matrix3d::Identity();
  c.anchors = {a};
  const std::string dir = tempDir("meshnav_checkpoint_anchors_period");
  writeCheckpoint(c, dir, /*with_anchors=*/false);  // no anchors' file yet: written
  ASSERT_EQ(readCheckpoint(dir)->anchors.size(), 1u);
  c.t = Timestamp::fromSec(1.1);
  c.anchors[0].p_AinG.x() = 1.5;
  writeCheckpoint(c, dir, false);
  auto back = readCheckpoint(dir);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->t, c.t);                      // the state: new
  EXPECT_EQ(back->anchors[0].p_AinG.x(), 1.0);  // the anchors: as written before
  writeCheckpoint(c, dir, true);
  EXPECT_EQ(readCheckpoint(dir)->anchors[0].p_AinG.x(), 1.5);
  EXPECT_TRUE(checkpointHasAnchorsFile(dir));
  EXPECT_FALSE(checkpointHasAnchorsFile(dir + "/absent"));
}

// The height bias converges in flight (true 0.25 m, prior 0 ± 0.3 m); the estimator dies at
// t = 15 s and restarts from the checkpoint files: the bias is there from the first IMU sample with
// its converged value and variance, and so are the tags' γ. Before issue 11 the checkpoint did not
// hold them: the height instance came back from its prior at the first height reading.
TEST(Checkpoint, ARestartKeepsTheHeightBiasAndTheTagGammas) {
  const Dataset ds = heightFlight(0.25);
  EstimatorNode before(EstimatorOptions{}, ds.setup);
  runUntil(before, ds, 15.0);
  ASSERT_TRUE(before.initialized());
  const NominalState& xb = before.filter()->state();
  ASSERT_EQ(xb.values<HeightBiasKind>().count(ds.setup.height_id), 1u);
  const double b_before = xb.values<HeightBiasKind>().at(ds.setup.height_id);
  const double var_before = before.filter()->covariance(ds.setup.height_id, ds.setup.height_id)(0, 0);
  ASSERT_NEAR(b_before, 0.25, 0.05);  // converged …
  ASSERT_LT(var_before, 0.1 * std::pow(EstimatorOptions{}.height.init_bias_sigma_m, 2));  // … and certain
  const Eigen::VectorXd gamma_before = xb.values<TagBiasKind>().at(100).gamma_m;
  const double var_gamma_before = before.filter()->covariance(100, 100)(0, 0);
  ASSERT_LT(var_gamma_before, 0.01);  // learnt from the prior σ² = 0.01

  const std::string dir = tempDir("meshnav_checkpoint_height");
  writeCheckpoint(before.checkpoint(), dir);
  EstimatorNode after(EstimatorOptions{}, ds.setup);
  after.resumeFrom(*readCheckpoint(dir));
  const Timestamp t_ckpt = xb.t;
  for (const auto& in : mergeInTimeOrder(ds)) {
    if (inputTime(in) <= t_ckpt) continue;
    after.onInput(in);
    if (after.initialized()) break;  // the first IMU sample after the checkpoint
  }
  ASSERT_TRUE(after.initialized());
  EXPECT_EQ(after.diagnostics().get("resumed"), 1);
  EXPECT_GE(after.diagnostics().get("resumed_instances"), 4);  // baro, height, two tags
  const NominalState& xa = after.filter()->state();
  ASSERT_EQ(xa.values<HeightBiasKind>().count(ds.setup.height_id), 1u) << "the height bias was not kept";
  EXPECT_NEAR(xa.values<HeightBiasKind>().at(ds.setup.height_id), b_before, 1e-9);
  const double dt = (xa.t - t_ckpt).sec();
  const double rw = EstimatorOptions{}.height.bias_rw_m_per_sqrt_s;
  EXPECT_NEAR(after.filter()->covariance(ds.setup.height_id, ds.setup.height_id)(0, 0), var_before + rw * rw * dt,
              1e-12);
  ASSERT_EQ(xa.values<TagBiasKind>().count(100), 1u);
  EXPECT_EQ(xa.values<TagBiasKind>().at(100).gamma_m, gamma_before);
  EXPECT_DOUBLE_EQ(after.filter()->covariance(100, 100)(0, 0), var_gamma_before);  // constant: no growth

  // The resumed estimator keeps estimating it: 5 s later still at the truth.
  runUntil(after, ds, 20.0, xa.t.sec());
  EXPECT_NEAR(after.filter()->state().values<HeightBiasKind>().at(ds.setup.height_id), 0.25, 0.05);
}

TEST(Checkpoint, AFileOfTheOldLayoutIsRefusedNamingTheFile) {
  const std::string dir = tempDir("meshnav_checkpoint_layout1");
  writeText(dir + "/estimator_state.yaml",
            "t: 1.0\np_IinG: [0, 0, 1]\nv_IinG: [0, 0, 0]\nq_ItoG: [0, 0, 0, 1]\nbaro_bias_m: 0.1\n");
  const std::string what = refusal(dir);
  EXPECT_NE(what.find("estimator_state.yaml"), std::string::npos) << what;
  EXPECT_NE(what.find("layout 1"), std::string::npos) << what;
  EXPECT_NE(what.find("version"), std::string::npos) << what;
}

TEST(Checkpoint, MalformedLayout2FilesAreRefusedNamingFileAndKey) {
  const std::string dir = tempDir("meshnav_checkpoint_malformed");
  const std::string file = dir + "/estimator_state.yaml";
  struct Case {
    std::string text, key;
  };
  const std::string header = kHeader, imu = imuRecord();
  const std::vector<Case> cases = {
      {"format: meshnav_estimator_state\nversion: 3\nt: 1.0\nlanded: false\ninstances: []\n", "version"},
      {"format: other\nversion: 2\nt: 1.0\nlanded: false\ninstances: []\n", "format"},
      {header, "instances"},
      {header + "  - kind: imu\n    id: 1\n    value: [0, 0, .nan]\n    cov: [1]\n", "instances[0].value"},
      {header + "  - kind: baro\n    id: 2\n    value: [0.1]\n    cov: [0.01]\n", "instances[0].kind"},
      {header + imu + "  - kind: baro\n    id: 2\n    value: [0.1, 0.2]\n    cov: [0.01]\n", "instances[1].kind"},
      {header + imu + "  - kind: baro\n    id: 2\n    value: [0.1]\n    cov: [-0.01]\n", "instances[1].kind"},
      {header + imu + "  - kind: baro\n    id: 2\n    value: [0.1]\n    cov: [1, 0]\n", "instances[1].cov"},
      {header + imu + "  - kind: wind\n    id: 9\n    value: [0.1]\n    cov: [1]\n", "instances[1].kind"},
      {header + imu + "  - kind: tag\n    id: 100\n    peers: [101]\n    value: [0.1, 0.2]\n    cov: [1]\n",
       "instances[1].kind"},
      {header + imu + "  - kind: baro\n    id: 2\n    value: [0.1]\n    cov: [1]\n    colour: red\n",
       "instances[1].colour"},
      {header + imu + "  - kind: height\n    id: 3\n    value: [0.1]\n    cov: [1]\n" +
           "  - kind: height\n    id: 3\n    value: [0.1]\n    cov: [1]\n",
       "instances[2].id"},
  };
  for (const Case& c : cases) {
    writeText(file, c.text);
    const std::string what = refusal(dir);
    EXPECT_NE(what.find("estimator_state.yaml"), std::string::npos) << c.text << "\n→ " << what;
    EXPECT_NE(what.find("'" + c.key + "'"), std::string::npos) << c.text << "\n→ " << what;
  }
  // A valid one with a kept baro bias is read.
  writeText(file, header + imu + "  - kind: baro\n    id: 2\n    value: [0.1]\n    cov: [0.01]\n");
  EXPECT_EQ(refusal(dir), "");
  EXPECT_FALSE(readCheckpoint(dir + "/absent").has_value());
}
