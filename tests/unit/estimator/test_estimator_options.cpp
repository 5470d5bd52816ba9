/// EstimatorOptions: the shipped YAML equals the built-in defaults; the one rule of options files
/// (common/yaml_options.h): missing keys keep defaults, unknown keys and bad values name file and key.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>

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
  // A key given twice (issue 36): the first used to win silently.
  e = loadError("opts_twice.yaml", "uwb:\n  sigma_range_m: 0.2\n  huber_k: 0\n  sigma_range_m: 0.3\n");
  EXPECT_NE(e.find(":4: key 'uwb.sigma_range_m' given twice (first at line 2)"), std::string::npos) << e;
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
  // refine.rerun_mode is a model parameter (auto does the right thing in the process and in replays).
  e = loadError("opts_rerun_mode.yaml", "refine:\n  rerun_mode: async\n");
  EXPECT_NE(e.find("key 'refine.rerun_mode' is a model parameter"), std::string::npos) << e;
  e = loadError("opts_fixed_lag.yaml", "fixed_lag:\n  lag_s: -1\n");
  EXPECT_NE(e.find("fixed_lag.lag_s in [0, 60]"), std::string::npos) << e;
  EXPECT_EQ(loadError("opts_fixed_lag_off.yaml", "fixed_lag:\n  lag_s: 0\n"), "");
  EstimatorOptions tiny_period;
  tiny_period.fixed_lag.period_s = 0.001;  // a model parameter: the C++ API
  EXPECT_THROW(tiny_period.validate(), std::invalid_argument);
  e = loadError("opts_huber.yaml", "uwb:\n  huber_k: -1\n");
  EXPECT_NE(e.find("uwb.huber_k >= 0"), std::string::npos) << e;
  EXPECT_EQ(loadError("opts_huber_on.yaml", "uwb:\n  huber_k: 2\n"), "");
  e = loadError("opts_profile.yaml", "profile: quadruped\n");
  EXPECT_NE(e.find("key 'profile' must be auto, drone or handheld, got 'quadruped'"), std::string::npos) << e;
}

// Issue 33: the models' fixed parameters are not options. A file written before (or by hand) that
// still sets one fails naming the file and the key, instead of being silently ignored.
TEST(EstimatorOptions, AModelParameterInAFileIsRefusedNamingFileAndKey) {
  const std::string path = (tempRoot() / "opts_model_param.yaml").string();
  std::string e = loadError("opts_model_param.yaml", "process_noise:\n  max_grow: 5.0\n");
  EXPECT_NE(e.find(path), std::string::npos) << e;
  EXPECT_NE(e.find("key 'process_noise.max_grow' is a model parameter"), std::string::npos) << e;
  e = loadError("opts_model_param2.yaml", "joseph_form: false\n");
  EXPECT_NE(e.find("key 'joseph_form' is a model parameter"), std::string::npos) << e;
  // Every model parameter is listed by --print-model-parameters, none by --print-config.
  const std::string options = EstimatorOptions{}.toString(), params = EstimatorOptions{}.modelParametersString();
  EXPECT_NE(params.find("  max_grow: 10.0"), std::string::npos) << params;
  EXPECT_EQ(options.find("max_grow"), std::string::npos);
  EXPECT_EQ(params.find("sigma_range_m"), std::string::npos);
}

TEST(EstimatorOptions, AtMostSixtyOptions) {
  // Issue 33, target: a user has at most 60 estimator options to know (one per line with a value).
  std::istringstream text(EstimatorOptions{}.toString());
  int options = 0;
  for (std::string line; std::getline(text, line);) options += line.find(": ") != std::string::npos;  // not "uwb:"
  EXPECT_GT(options, 40);
  EXPECT_LE(options, 60);
}

// The model parameters keep their ranges, checked by validate() for the C++ API (tests, tools).
TEST(EstimatorOptions, ModelParametersAreValidated) {
  auto invalid = [](auto&& change) {
    EstimatorOptions o;
    change(o);
    try {
      o.validate();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(invalid([](EstimatorOptions& o) { o.process_noise.batch = 4; }).find("batch >= 5"), std::string::npos);
  EXPECT_NE(invalid([](EstimatorOptions& o) { o.process_noise.max_grow = 1.0; }).find("max_grow > 1"),
            std::string::npos);
  EXPECT_NE(invalid([](EstimatorOptions& o) { o.uwb.dah_joint_max_anchors = -1; }).find("uwb.dah_joint_max_anchors >= 0"),
            std::string::npos);
  EXPECT_EQ(invalid([](EstimatorOptions& o) { o.uwb.huber_max_prior_ratio = 0.5; }), "");
}

// The profile gives the defaults of its platform's models; the file's other keys override them.
TEST(EstimatorOptions, ProfileSetsThePlatformModelsAndKeysOverrideIt) {
  EXPECT_EQ(EstimatorOptions::fromYaml(tempFile("p_auto.yaml", "profile: auto\n")).toString(),
            EstimatorOptions{}.toString());
  const auto drone = EstimatorOptions::fromYaml(tempFile("p_drone.yaml", "profile: drone\n"));
  EXPECT_FALSE(drone.carried_height.enabled);
  EXPECT_TRUE(drone.height.enabled);
  const auto hand = EstimatorOptions::fromYaml(tempFile("p_hand.yaml", "profile: handheld\n"));
  EXPECT_FALSE(hand.height.enabled);
  EXPECT_TRUE(hand.carried_height.enabled);
  const auto over = EstimatorOptions::fromYaml(tempFile("p_over.yaml", "profile: handheld\nheight:\n  enabled: true\n"));
  EXPECT_TRUE(over.height.enabled);
  // What is printed loads back as the same options, profile included.
  const auto back = EstimatorOptions::fromYaml(tempFile("p_back.yaml", hand.toString()));
  EXPECT_EQ(back.toString(), hand.toString());
  EXPECT_EQ(back.profile, "handheld");
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
