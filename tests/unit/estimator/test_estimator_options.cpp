/// EstimatorOptions: the shipped YAML equals the built-in defaults; the one rule of options files
/// (common/yaml_options.h): missing keys keep defaults, unknown keys and bad values name file and key.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "estimator/core/estimator_options.h"
#include "tests/support/test_util.h"

using namespace meshnav::estimator;

namespace {
/// This binary's private temp folder, removed at exit.
const meshnav::test::TempDir& tempRoot() {
  static const meshnav::test::TempDir root("estimator_options");
  return root;
}

std::string tempFile(const std::string& name, const std::string& text) {
  return meshnav::test::writeFile(tempRoot() / name, text);
}
}  // namespace

TEST(EstimatorOptions, ShippedConfigEqualsDefaults) {
  const auto o = EstimatorOptions::fromYaml(std::string(MESHNAV_SOURCE_DIR) + "/config/estimator.yaml");
  EXPECT_EQ(o.toString(), EstimatorOptions{}.toString());
}

TEST(EstimatorOptions, PrintedOptionsLoadBack) {
  EstimatorOptions o;
  o.window_s = 0.5;
  o.uwb.sigma_range_m = 0.3;
  o.zupt.enabled = false;
  o.init.min_ranges = 20;
  const auto back = EstimatorOptions::fromYaml(tempFile("opts_roundtrip.yaml", o.toString()));
  EXPECT_EQ(back.toString(), o.toString());
  EXPECT_DOUBLE_EQ(back.uwb.sigma_range_m, 0.3);
  EXPECT_FALSE(back.zupt.enabled);
}

TEST(EstimatorOptions, MissingKeyKeepsItsDefault) {
  // One rule for every options file (issue 11): a missing key takes its documented default.
  std::string text = EstimatorOptions{}.toString();
  const auto pos = text.find("  sigma_vel_m_s");
  text.erase(pos, text.find('\n', pos) - pos + 1);
  text.replace(text.find("window_s: 1.0"), 13, "window_s: 0.5");
  const auto o = EstimatorOptions::fromYaml(tempFile("opts_missing.yaml", text));
  EXPECT_DOUBLE_EQ(o.zupt.sigma_vel_m_s, EstimatorOptions{}.zupt.sigma_vel_m_s);
  EXPECT_DOUBLE_EQ(o.window_s, 0.5);
  EXPECT_EQ(EstimatorOptions::fromYaml(tempFile("opts_empty.yaml", "")).toString(), EstimatorOptions{}.toString());
}

namespace {
/// The message of the error loading `text`, or "" when it loads.
std::string loadError(const std::string& name, const std::string& text) {
  try {
    EstimatorOptions::fromYaml(tempFile(name, text));
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(EstimatorOptions, UnknownKeysAndBadValuesNameFileAndKey) {
  // Issue 12, finding 4 / issue 11: a misspelled key used to be ignored.
  const std::string path = (tempRoot() / "opts_typo.yaml").string();
  std::string e = loadError("opts_typo.yaml", "uwb:\n  sigma_range_mm: 0.2\n");
  EXPECT_NE(e.find(path), std::string::npos) << e;
  EXPECT_NE(e.find("unknown key 'uwb.sigma_range_mm'"), std::string::npos) << e;
  e = loadError("opts_top.yaml", "windw_s: 1.0\n");
  EXPECT_NE(e.find("unknown key 'windw_s'"), std::string::npos) << e;
  e = loadError("opts_section.yaml", "zuptt:\n  enabled: false\n");
  EXPECT_NE(e.find("unknown key 'zuptt'"), std::string::npos) << e;
  e = loadError("opts_inf.yaml", "uwb:\n  sigma_range_m: .inf\n");
  EXPECT_NE(e.find("key 'uwb.sigma_range_m' must be a finite number, got '.inf'"), std::string::npos) << e;
  e = loadError("opts_type.yaml", "init:\n  min_ranges: twelve\n");
  EXPECT_NE(e.find("key 'init.min_ranges' must be an integer, got 'twelve'"), std::string::npos) << e;
  e = loadError("opts_list.yaml", "gravity_m_s2: [9.81]\n");
  EXPECT_NE(e.find("key 'gravity_m_s2' must be a single value"), std::string::npos) << e;
  e = loadError("opts_scalar_section.yaml", "uwb: 3\n");
  EXPECT_NE(e.find("'uwb' must be a map"), std::string::npos) << e;
  e = loadError("opts_time.yaml", "time:\n  max_offset_s: 0.5\n");  // below window_s
  EXPECT_NE(e.find("time.max_offset_s >= window_s"), std::string::npos) << e;
  e = loadError("opts_rerun_mode.yaml", "refine:\n  rerun_mode: threaded\n");
  EXPECT_NE(e.find("refine.rerun_mode must be auto, sync or async"), std::string::npos) << e;
  EXPECT_EQ(loadError("opts_rerun_async.yaml", "refine:\n  rerun_mode: async\n"), "");
  e = loadError("opts_pn_fraction.yaml", "process_noise:\n  min_accepted_fraction: 0\n");
  EXPECT_NE(e.find("min_accepted_fraction in (0, 1]"), std::string::npos) << e;
  e = loadError("opts_pn_confirm.yaml", "process_noise:\n  confirm_batches: 0\n");
  EXPECT_NE(e.find("confirm_batches >= 1"), std::string::npos) << e;
  e = loadError("opts_pn_at_once.yaml", "process_noise:\n  grow_at_once_ratio: 2.0\n");  // below upper_ratio
  EXPECT_NE(e.find("grow_at_once_ratio >= upper_ratio"), std::string::npos) << e;
  e = loadError("opts_huber.yaml", "uwb:\n  huber_k: -1\n");
  EXPECT_NE(e.find("uwb.huber_k >= 0"), std::string::npos) << e;
  EXPECT_EQ(loadError("opts_huber_on.yaml", "uwb:\n  huber_k: 2\n  huber_max_prior_ratio: 0.5\n"), "");
  EXPECT_EQ(loadError("opts_pn_no_ratchet.yaml", "process_noise:\n  min_accepted_fraction: 0.5\n  confirm_batches: 2\n"), "");
  e = loadError("opts_joint_max.yaml", "uwb:\n  dah_joint_max_anchors: -1\n");
  EXPECT_NE(e.find("uwb.dah_joint_max_anchors >= 0"), std::string::npos) << e;
}

TEST(EstimatorOptions, InvalidValuesAndFilesAreRejected) {
  std::string text = EstimatorOptions{}.toString();
  const auto pos = text.find("window_s: 1.0");
  text.replace(pos, 13, "window_s: -1.0");
  EXPECT_THROW(EstimatorOptions::fromYaml(tempFile("opts_bad.yaml", text)), std::runtime_error);
  EXPECT_THROW(EstimatorOptions::fromYaml("/nonexistent/estimator.yaml"), std::runtime_error);
}

TEST(EstimatorOptions, SetupNoiseOverridesImuAndBaro) {
  EstimatorOptions o;
  meshnav::NoiseFigures n;
  n.imu_acc_noise_density = 0.003;
  n.baro_pressure_sigma_pa = 1.5;
  o.applySetupNoise(n);
  EXPECT_DOUBLE_EQ(o.imu.acc_noise_density, 0.003);
  EXPECT_DOUBLE_EQ(o.baro.pressure_sigma_pa, 1.5);
  EXPECT_DOUBLE_EQ(o.imu.gyro_noise_density, EstimatorOptions{}.imu.gyro_noise_density);
  EXPECT_DOUBLE_EQ(o.init.sigma_bias_acc_m_s2, EstimatorOptions{}.init.sigma_bias_acc_m_s2);
  // A datasheet's switch-on bias spread becomes the bias prior of every initialization.
  n.imu_acc_bias_sigma = 0.01;
  n.imu_gyro_bias_sigma = 5e-4;
  o.applySetupNoise(n);
  EXPECT_DOUBLE_EQ(o.init.sigma_bias_acc_m_s2, 0.01);
  EXPECT_DOUBLE_EQ(o.init.sigma_bias_gyro_rad_s, 5e-4);
}

TEST(EstimatorOptions, Chi2Quantiles) {
  EXPECT_NEAR(chi2Quantile(1, 0.997), 8.8075, 1e-3);
  EXPECT_NEAR(chi2Quantile(1, 0.95), 3.8415, 1e-3);
  EXPECT_NEAR(chi2Quantile(3, 0.99), 11.345, 1e-3);
  EXPECT_NEAR(chi2Quantile(9, 0.999), 27.877, 1e-2);
}
