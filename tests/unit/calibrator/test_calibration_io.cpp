// Calibration YAML round trip, options YAML, and building observations from ranges + poses.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "calibrator/anchor_calibrator.h"
#include "calibrator/calibration_io.h"
#include "calibrator/node/calibrator_config.h"
#include "common/anchor_init_io.h"
#include "calibrator/observation_builder.h"
#include "calibrator/synthetic_scene.h"
#include "tests/support/test_util.h"

using namespace meshnav;
using namespace meshnav::calib;

namespace {
std::string tmpFile(const std::string& name) {
  static const meshnav::test::TempDir dir("calib_test");  // removed at exit
  return (dir / name).string();
}
}  // namespace

TEST(CalibrationIo, YamlRoundTripIntoAnchorInit) {
  SyntheticSceneConfig cfg;
  const auto sc = makeSyntheticScene(cfg);
  CalibrationResult ok = AnchorCalibrator({}).calibrate(106, sc.observations, {}, Timestamp::fromSec(80.0));
  ASSERT_TRUE(ok.ok());
  CalibrationResult refused = AnchorCalibrator({}).calibrate(109, {}, {}, Timestamp::fromSec(80.0));
  const std::string path = tmpFile("calib.yaml");
  writeCalibrationYaml({ok, refused}, path);
  const auto inits = readAnchorInitsYaml(path);
  ASSERT_EQ(inits.size(), 1u);
  const AnchorInit& a = inits[0];
  EXPECT_EQ(a.id, 106);
  EXPECT_NEAR(a.t.sec(), 80.0, 1e-9);
  EXPECT_LT((a.p_AinG - ok.p_AinG).norm(), 1e-8);
  EXPECT_LT((a.cov_p_m2 - ok.cov_p_m2).norm(), 1e-12);
  EXPECT_EQ(a.n_inliers, ok.n_inliers);
  EXPECT_EQ(a.n_outliers, ok.n_outliers);
  ASSERT_EQ(a.biases.size(), ok.references.size());
  for (size_t k = 0; k < a.biases.size(); ++k) {
    EXPECT_EQ(a.biases[k].a, ok.references[k].ref_id);
    EXPECT_EQ(a.biases[k].b, 106);
    EXPECT_NEAR(a.biases[k].gamma_m, ok.references[k].gamma_m, 1e-8);
    EXPECT_NEAR(a.biases[k].beta, ok.references[k].beta, 1e-8);
    EXPECT_NEAR(a.biases[k].sigma_gamma_m, ok.references[k].sigma_gamma_m, 1e-8);
  }
  // The joint covariance of position and γ (issue 10): the calibration's own blocks, back unchanged.
  const auto n = static_cast<Eigen::Index>(ok.references.size());
  ASSERT_EQ(ok.cov_p_gamma_m2.rows(), 3 + n);
  EXPECT_LT((ok.cov_p_gamma_m2.topLeftCorner<3, 3>() - ok.cov_p_m2).norm(), 1e-15);
  for (Eigen::Index k = 0; k < n; ++k)
    EXPECT_NEAR(std::sqrt(ok.cov_p_gamma_m2(3 + k, 3 + k)), ok.references[static_cast<size_t>(k)].sigma_gamma_m, 1e-12);
  ASSERT_TRUE(a.hasJointCovariance());
  EXPECT_LT((a.jointCovariance() - ok.cov_p_gamma_m2).norm(), 1e-12 * ok.cov_p_gamma_m2.norm());
  // The γ of the moving tags are correlated with the position, not independent of it.
  EXPECT_GT(a.cov_gamma_p_m2.cwiseAbs().maxCoeff(), 1e-3 * std::sqrt(a.cov_p_m2.trace() * a.cov_gamma_m2.trace()));
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const char* key : {"p_AinG_cov", "ref_ids", "const_biases", "dist_biases", "sigma_const_biases",
                          "sigma_dist_biases", "n_inliers", "n_outliers", "refused", "too_few_measurements",
                          "cov_gamma_p", "cov_gamma"})
    EXPECT_NE(text.find(key), std::string::npos) << key;
}

TEST(CalibrationIo, JointCovarianceIsOptionalAndChecked) {
  const std::string base = "anchors:\n  - {id: 109, p_AinG: [1, 2, 3], p_AinG_cov: [1, 0, 0, 0, 1, 0, 0, 0, 1], "
                           "ref_ids: [100, 101], const_biases: [0.1, 0.2], dist_biases: [1, 1], "
                           "sigma_const_biases: [0.02, 0.03], sigma_dist_biases: [0, 0]";
  const std::string path = tmpFile("joint.yaml");
  {
    std::ofstream(path) << base << "}\n";  // a file written before issue 10
  }
  auto inits = readAnchorInitsYaml(path);
  ASSERT_EQ(inits.size(), 1u);
  EXPECT_FALSE(inits[0].hasJointCovariance());
  EXPECT_DOUBLE_EQ(inits[0].jointCovariance()(4, 4), 0.03 * 0.03);
  {
    std::ofstream(path) << base << ", cov_gamma_p: [0.1, 0.2, 0.3, 0.4, 0.5, 0.6], cov_gamma: [0.0004, 1e-5, 1e-5, 0.0009]}\n";
  }
  inits = readAnchorInitsYaml(path);
  ASSERT_TRUE(inits[0].hasJointCovariance());
  EXPECT_EQ(inits[0].cov_gamma_p_m2(1, 0), 0.4);  // row-major: γ_1 with x
  EXPECT_EQ(inits[0].cov_gamma_m2(0, 1), 1e-5);
  for (const std::string bad : {", cov_gamma_p: [0.1, 0.2, 0.3], cov_gamma: [1, 0, 0, 1]}",
                                ", cov_gamma_p: [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]}",
                                ", cov_gamma_p: [0.1, 0.2, 0.3, 0.4, 0.5, .nan], cov_gamma: [1, 0, 0, 1]}"}) {
    {
      std::ofstream(path) << base << bad << "\n";
    }
    try {
      readAnchorInitsYaml(path);
      FAIL() << "no throw for " << bad;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("anchors[0].cov_gamma"), std::string::npos) << e.what();
    }
  }
}

TEST(CalibrationIo, MalformedYamlNamesFileAndKey) {
  const std::string path = tmpFile("bad.yaml");
  {
    std::ofstream(path) << "anchors:\n  - id: 106\n    p_AinG: [1, 2]\n";
  }
  try {
    readAnchorInitsYaml(path);
    FAIL() << "no throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("anchors[0].p_AinG"), std::string::npos) << e.what();
  }
  EXPECT_THROW(readAnchorInitsYaml(tmpFile("missing.yaml")), std::runtime_error);
}

// Found by fuzz target anchor_init_yaml (UBSan: 1e+20 cast to int): reference ids that are not
// device ids, and values that are not finite, are refused naming file and key.
TEST(CalibrationIo, RefIdsAndNonFiniteValuesAreRefused) {
  const std::string path = tmpFile("bad_ids.yaml");
  const std::string entry = "anchors:\n  - {id: 109, p_AinG: %P, p_AinG_cov: [1, 0, 0, 0, 1, 0, 0, 0, 1], ref_ids: %R, "
                            "const_biases: [0], dist_biases: [1], sigma_const_biases: [0], sigma_dist_biases: [0]}\n";
  const struct {
    const char* p;
    const char* refs;
    const char* key;
  } cases[] = {{"[1, 2, 3]", "[1e20]", "anchors[0].ref_ids"},
               {"[1, 2, 3]", "[-1]", "anchors[0].ref_ids"},
               {"[1, 2, 3]", "[100.5]", "anchors[0].ref_ids"},
               {"[1, 2, 3]", "[.nan]", "anchors[0].ref_ids"},
               {"[1, .inf, 3]", "[100]", "anchors[0].p_AinG"}};
  for (const auto& c : cases) {
    std::string text = entry;
    text.replace(text.find("%P"), 2, c.p);
    text.replace(text.find("%R"), 2, c.refs);
    std::ofstream(path) << text;
    try {
      readAnchorInitsYaml(path);
      ADD_FAILURE() << "accepted " << text;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path + ": key '" + c.key + "'"), std::string::npos) << e.what();
    }
  }
  std::ofstream(path) << [&] {
    std::string text = entry;
    text.replace(text.find("%P"), 2, "[1, 2, 3]");
    text.replace(text.find("%R"), 2, "[2147483647]");
    return text;
  }();
  const auto inits = readAnchorInitsYaml(path);
  ASSERT_EQ(inits.size(), 1u);
  ASSERT_EQ(inits[0].biases.size(), 1u);
  EXPECT_EQ(inits[0].biases[0].a, 2147483647);
}

TEST(CalibrationIo, OptionsFromYaml) {
  const std::string path = tmpFile("opts.yaml");
  {
    std::ofstream(path) << "calibrator:\n  sigma_range: 0.2\n  robust_loss: huber\n  ransac: false\n";
  }
  const auto o = CalibratorConfig::load(path).calibrator;
  EXPECT_DOUBLE_EQ(o.sigma_range_m, 0.2);
  EXPECT_EQ(o.robust_loss, RobustLoss::Huber);
  EXPECT_FALSE(o.ransac);
  EXPECT_NE(o.toString().find("robust_loss: huber"), std::string::npos);
  {
    std::ofstream(path) << "calibrator:\n  sigma_rnage: 0.2\n";
  }
  try {
    CalibratorConfig::load(path).calibrator;
    FAIL() << "no throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("sigma_rnage"), std::string::npos);
  }
  {
    std::ofstream(path) << "calibrator:\n  sigma_range: -1\n";
  }
  EXPECT_THROW(CalibratorConfig::load(path).calibrator, std::runtime_error);
  // The one rule (issue 11, issue 12 item 5): non-finite and mistyped values name file and key,
  // unknown keys in either map or at the top are refused.
  auto error = [&](const std::string& text) -> std::string {
    std::ofstream(path) << text;
    try {
      CalibratorConfig::load(path);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(error("calibrator:\n  sigma_range: .inf\n").find(path + ": key 'calibrator.sigma_range' must be a finite number"),
            std::string::npos);
  EXPECT_NE(error("calibrator:\n  min_measurements: thirty\n").find("key 'calibrator.min_measurements' must be an integer"),
            std::string::npos);
  EXPECT_NE(error("calibrator:\n  robust_loss: tukey\n").find("key 'calibrator.robust_loss' robust_loss must be"),
            std::string::npos);
  EXPECT_NE(error("calibrator_node:\n  auto_mod: true\n").find("unknown key 'calibrator_node.auto_mod'"),
            std::string::npos);
  EXPECT_NE(error("calibrator: {}\ncalibratr_node: {}\n").find("unknown key 'calibratr_node'"), std::string::npos);
  EXPECT_NE(error("calibrator_node:\n  time_max_offset: 0\n").find("calibrator_node.time_max_offset"), std::string::npos);
  EXPECT_EQ(error("calibrator_node:\n  auto_mode: true\n"), "");  // the other map keeps its defaults
}

TEST(ObservationBuilder, ATagIsTakenWhereItWasWhenTheLateStampedRangeWasMeasured) {
  // setup.yaml uwb_clock.offset_s: a range stamped t was measured at the IMU-clock instant t − 0.25 s.
  SystemSetup setup;
  setup.rel_tag_positions[100] = Eigen::Vector3d::Zero();
  setup.uwb_clock.offset_s = 0.25;
  CalibratorOptions o;
  o.max_pose_gap_s = 2.0;  // the two poses below are 1 s apart
  ObservationBuilder b(setup, o);
  std::vector<PoseEstimate> poses(2);
  poses[1].t = Timestamp::fromSec(1.0);
  poses[1].p_IinG = Eigen::Vector3d(2, 0, 0);  // 2 m/s along x
  b.setPoses(poses);
  RangeSample r;
  r.t = Timestamp::fromSec(0.75);
  r.id_initiator = 100;
  r.id_responder = 106;
  r.range_m = 3.0;
  Diagnostics diag;
  const auto obs = b.collect(106, {r}, diag);
  ASSERT_EQ(obs.size(), 1u);
  EXPECT_LT((obs[0].p_RinG - Eigen::Vector3d(1.0, 0, 0)).norm(), 1e-9);  // at 0.5 s, not 1.5 m at 0.75 s
}

TEST(ObservationBuilder, TagsAtLeverArmKnownAnchorsAndDiagnostics) {
  SystemSetup setup;
  setup.rel_tag_positions[100] = Eigen::Vector3d(0.2, 0.0, -0.1);
  setup.abs_anchor_positions[101] = Eigen::Vector3d(1, 2, 3);
  setup.abs_anchor_positions[106] = Eigen::Vector3d(9, 9, 9);  // known, but calibrated as unknown
  setup.abs_anchor_sigmas_m[101] = 0.05;
  setup.pair_biases.push_back(PairBias{101, 106, 0.3, 1.0, 0.1, 0.02, 0.0});
  CalibratorOptions o;
  o.max_pose_gap_s = 2.0;
  ObservationBuilder b(setup, o);
  std::vector<PoseEstimate> poses(2);
  poses[0].t = Timestamp::fromSec(0.0);
  poses[1].t = Timestamp::fromSec(1.0);
  poses[1].p_IinG = Eigen::Vector3d(2, 0, 0);
  for (auto& p : poses) {
    p.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
    p.cov_p_m2 = 0.01 * Eigen::Matrix3d::Identity();
    p.cov_theta_rad2 = 0.0 * Eigen::Matrix3d::Identity();
  }
  b.setPoses(poses);
  auto mk = [](double t, SensorId a, SensorId c, double z) {
    RangeSample r;
    r.t = Timestamp::fromSec(t);
    r.id_initiator = a;
    r.id_responder = c;
    r.range_m = z;
    return r;
  };
  const std::vector<RangeSample> ranges = {mk(0.5, 100, 106, 3.0), mk(0.5, 106, 101, 4.0), mk(5.0, 100, 106, 3.0),
                                           mk(0.6, 107, 106, 2.0), mk(0.7, 100, 101, 2.0),
                                           mk(0.8, 106, 100, std::nan(""))};
  Diagnostics diag;
  const auto obs = b.collect(106, ranges, diag);
  ASSERT_EQ(obs.size(), 2u);
  EXPECT_EQ(obs[0].ref_id, 100);
  EXPECT_LT((obs[0].p_RinG - Eigen::Vector3d(1.0, 0.2, -0.1)).norm(), 1e-12);  // p + R_z(90°)·l
  EXPECT_NEAR(obs[0].cov_p_RinG_m2(0, 0), 0.01, 1e-12);
  EXPECT_EQ(obs[1].ref_id, 101);
  EXPECT_EQ(obs[1].p_RinG, Eigen::Vector3d(1, 2, 3));
  EXPECT_NEAR(obs[1].cov_p_RinG_m2(2, 2), 0.0025, 1e-12);
  EXPECT_EQ(diag.get("calibrator:range_without_pose"), 1);
  EXPECT_EQ(diag.get("calibrator:range_to_unknown_device"), 1);
  EXPECT_EQ(diag.get("calibrator:bad_range"), 1);
  const auto pri = b.priors(106);
  ASSERT_EQ(pri.count(101), 1u);
  EXPECT_DOUBLE_EQ(pri.at(101).gamma_m, 0.3);
  EXPECT_DOUBLE_EQ(pri.at(101).sigma_gamma_m, 0.02);
  // Time window.
  EXPECT_EQ(b.collect(106, ranges, diag, Timestamp::fromSec(0.55), std::nullopt).size(), 0u);
}
