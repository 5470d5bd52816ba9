/// EstimatorOptions: the shipped YAML equals the built-in defaults, missing keys name file and key.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "estimator/core/estimator_options.h"

using namespace meshnav::estimator;

namespace {
std::string tempFile(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
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

TEST(EstimatorOptions, MissingKeyNamesFileAndKey) {
  std::string text = EstimatorOptions{}.toString();
  const auto pos = text.find("  sigma_vel_m_s");
  text.erase(pos, text.find('\n', pos) - pos + 1);
  const std::string path = tempFile("opts_missing.yaml", text);
  try {
    EstimatorOptions::fromYaml(path);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("zupt.sigma_vel_m_s"), std::string::npos) << e.what();
  }
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
}

TEST(EstimatorOptions, Chi2Quantiles) {
  EXPECT_NEAR(chi2Quantile(1, 0.997), 8.8075, 1e-3);
  EXPECT_NEAR(chi2Quantile(1, 0.95), 3.8415, 1e-3);
  EXPECT_NEAR(chi2Quantile(3, 0.99), 11.345, 1e-3);
  EXPECT_NEAR(chi2Quantile(9, 0.999), 27.877, 1e-2);
}
