#include <gtest/gtest.h>

#include "tests/support/shared_data.h"

#include <filesystem>

#include "common/setup.h"
#include "tests/support/test_util.h"

using namespace meshnav;

namespace {
SystemSetup sample() {
  SystemSetup s;
  s.rel_tag_positions[100] = {-0.19, 0.105, -0.07};
  s.rel_tag_positions[105] = {0.05, -0.105, -0.07};
  s.abs_anchor_positions[101] = {-1.308, -4.140, 0.66};
  s.abs_anchor_positions[102] = {1.742, -4.147, 1.881};
  s.abs_anchor_sigmas_m[102] = 0.3;
  s.pair_biases.push_back({100, 101, 0.12, 1.001, 0.1});
  s.baro_p_IP = {0, 0, 0.05};
  InitialPose ip;
  ip.p_IinG = {1, 2, 0.1};
  ip.yaw_deg = 30;
  s.initial_pose = ip;
  s.noise.sigma_range_m = 0.15;
  return s;
}
}  // namespace

TEST(Setup, RoundTrip) {
  const test::TempDir d("setup");
  const auto s = sample();
  saveSetup(s, (d / "setup.yaml").string());
  const auto r = loadSetup((d / "setup.yaml").string());
  EXPECT_EQ(r.imu_id, 1);
  EXPECT_EQ(r.rel_tag_positions.size(), 2u);
  EXPECT_TRUE(r.rel_tag_positions.at(105).isApprox(s.rel_tag_positions.at(105)));
  EXPECT_TRUE(r.abs_anchor_positions.at(102).isApprox(s.abs_anchor_positions.at(102)));
  EXPECT_DOUBLE_EQ(r.abs_anchor_sigmas_m.at(102), 0.3);
  ASSERT_TRUE(r.findPairBias(101, 100));
  EXPECT_DOUBLE_EQ(r.findPairBias(101, 100)->gamma_m, 0.12);
  EXPECT_FALSE(r.findPairBias(100, 102));
  EXPECT_FALSE(r.baro_reference_pressure_pa);
  ASSERT_TRUE(r.initial_pose);
  EXPECT_DOUBLE_EQ(r.initial_pose->yaw_deg, 30);
  EXPECT_DOUBLE_EQ(*r.noise.sigma_range_m, 0.15);
  EXPECT_FALSE(r.noise.imu_acc_bias_rw);
  EXPECT_EQ(r.height_id, 3);
  EXPECT_TRUE(r.height_p_IH.isZero());
  // The rangefinder's id and lever arm, written only when not the defaults.
  auto h = s;
  h.height_id = 7;
  h.height_p_IH = Eigen::Vector3d(0.02, 0.0, -0.11);
  saveSetup(h, (d / "height.yaml").string());
  const auto rh = loadSetup((d / "height.yaml").string());
  EXPECT_EQ(rh.height_id, 7);
  EXPECT_TRUE(rh.height_p_IH.isApprox(h.height_p_IH));
  EXPECT_EQ(rh.uwb_clock_id, 4);
  EXPECT_FALSE(rh.uwb_clock.sigma_s);
  // The UWB clock's id and prior, written only when not the defaults.
  auto clock = s;
  clock.uwb_clock_id = 9;
  clock.uwb_clock = UwbClock{-0.03, 0.0};
  saveSetup(clock, (d / "clock.yaml").string());
  const auto r_clock = loadSetup((d / "clock.yaml").string());
  EXPECT_EQ(r_clock.uwb_clock_id, 9);
  EXPECT_DOUBLE_EQ(r_clock.uwb_clock.offset_s, -0.03);
  ASSERT_TRUE(r_clock.uwb_clock.sigma_s);
  EXPECT_EQ(*r_clock.uwb_clock.sigma_s, 0.0);
  EXPECT_FALSE(rh.carried_height);
  // A hand-held rig's carrying height, written only when given.
  auto c = s;
  c.carried_height = CarriedHeight{1.35, 0.25};
  saveSetup(c, (d / "carried.yaml").string());
  const auto rc = loadSetup((d / "carried.yaml").string());
  ASSERT_TRUE(rc.carried_height);
  EXPECT_DOUBLE_EQ(rc.carried_height->height_m, 1.35);
  EXPECT_DOUBLE_EQ(rc.carried_height->sigma_m, 0.25);
  EXPECT_FALSE(rc.noise.imu_acc_bias_sigma);
  EXPECT_FALSE(rc.flight_volume);
  // The flight volume, written only when given.
  auto v = s;
  v.flight_volume = FlightVolume{Eigen::Vector3d(-2.5, -4.2, 0.0), Eigen::Vector3d(3.0, 4.2, 8.2)};
  saveSetup(v, (d / "volume.yaml").string());
  const auto rv = loadSetup((d / "volume.yaml").string());
  ASSERT_TRUE(rv.flight_volume);
  EXPECT_TRUE(rv.flight_volume->min_m.isApprox(v.flight_volume->min_m));
  EXPECT_TRUE(rv.flight_volume->max_m.isApprox(v.flight_volume->max_m));
  EXPECT_DOUBLE_EQ(rv.flight_volume->distanceOutside(Eigen::Vector3d(0.0, 0.0, 1.0)), 0.0);
  EXPECT_DOUBLE_EQ(rv.flight_volume->distanceOutside(Eigen::Vector3d(4.0, 0.0, -1.0)), std::sqrt(2.0));
  // The IMU's switch-on bias spread, written only when given.
  auto b = s;
  b.noise.imu_acc_bias_sigma = 0.01;
  b.noise.imu_gyro_bias_sigma = 5e-4;
  saveSetup(b, (d / "bias.yaml").string());
  const auto rb = loadSetup((d / "bias.yaml").string());
  ASSERT_TRUE(rb.noise.imu_acc_bias_sigma && rb.noise.imu_gyro_bias_sigma);
  EXPECT_DOUBLE_EQ(*rb.noise.imu_acc_bias_sigma, 0.01);
  EXPECT_DOUBLE_EQ(*rb.noise.imu_gyro_bias_sigma, 5e-4);
  // The unlisted pairs' bias σ, 0 included (calibrated ranges), written only when given.
  EXPECT_FALSE(rb.noise.sigma_gamma_m);
  auto g = s;
  g.noise.sigma_gamma_m = 0.0;
  g.noise.range_correlation_time_s = 0.0;
  saveSetup(g, (d / "gamma.yaml").string());
  const auto rg = loadSetup((d / "gamma.yaml").string());
  ASSERT_TRUE(rg.noise.sigma_gamma_m);
  EXPECT_DOUBLE_EQ(*rg.noise.sigma_gamma_m, 0.0);
  ASSERT_TRUE(rg.noise.range_correlation_time_s);
  EXPECT_DOUBLE_EQ(*rg.noise.range_correlation_time_s, 0.0);
}

TEST(Setup, ReadsThePublishedToolboxConfig) {
  const std::string f = std::string(MESHNAV_SHARED_DIR) + "/data/real-t1-a3-loiter/config.yaml";
  MESHNAV_REQUIRE_SHARED_DATA(f);
  const auto s = loadSetup(f);
  ASSERT_EQ(s.rel_tag_positions.size(), 1u);
  EXPECT_TRUE(s.rel_tag_positions.at(0).isApprox(Eigen::Vector3d(-0.09, 0.04, -0.045)));
  ASSERT_EQ(s.abs_anchor_positions.size(), 3u);
  EXPECT_TRUE(s.abs_anchor_positions.at(3).isApprox(Eigen::Vector3d(2.928, 2.47, 2.153)));
}

TEST(Setup, MalformedFilesNameFileAndKey) {
  const test::TempDir d("setup");
  auto expectError = [&](const std::string& text, const std::string& needle) {
    auto f = test::writeFile(d / "bad.yaml", text);
    try {
      loadSetup(f);
      ADD_FAILURE() << "expected an error for: " << text;
    } catch (const std::runtime_error& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("bad.yaml"), std::string::npos) << m;
      EXPECT_NE(m.find(needle), std::string::npos) << m;
    }
  };
  expectError("rel_tag_positions: {100: [1, 2]}\n", "rel_tag_positions.100");
  expectError("abs_anchor_positions: {101: [1, 2, x]}\n", "abs_anchor_positions.101");
  expectError("pair_biases: [{ids: [1]}]\n", "pair_biases[0].ids");
  expectError("pair_biases: [{ids: [1, 1]}]\n", "same device");
  // One model per pair, in either order (the estimator kept the last, findPairBias the first).
  expectError("pair_biases: [{ids: [100, 101], gamma: 0.1}, {ids: [101, 100], gamma: -0.2}]\n",
              "key 'pair_biases[1].ids' names the pair 101–100 of 'pair_biases[0]' again");
  expectError("initial_pose: {p_IinG: [0, 0, 0], sigma_p: 0.1}\n", "initial_pose.yaw_deg");
  expectError("rel_tag_positions: {5: [0,0,0]}\nabs_anchor_positions: {5: [0,0,0]}\n", "both a tag and an anchor");
  expectError("a: [1, 2\n", "YAML syntax error");
  expectError("abs_anchor_sigmas: {7: 0.3}\n", "abs_anchor_sigmas.7");
  EXPECT_THROW(loadSetup((d / "missing.yaml").string()), std::runtime_error);
}

TEST(Setup, BadConfigurationIsRefusedWithFileAndKey) {
  // Issue 12, finding 4 and item 5; issue 11 "options files: one rule".
  const test::TempDir d("setup");
  const std::string base =
      "rel_tag_positions: {100: [0, 0, 0], 105: [0.1, 0, 0]}\n"
      "abs_anchor_positions: {101: [1, 2, 3], 102: [3, 2, 1]}\n";
  auto error = [&](const std::string& text) -> std::string {
    const auto f = test::writeFile(d / "setup.yaml", text);
    try {
      loadSetup(f);
    } catch (const std::runtime_error& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(f), std::string::npos) << m;  // always the file
      return m;
    }
    return "";
  };
  EXPECT_NE(error(base + "abs_anchor_positons: {103: [0, 0, 0]}\n").find("unknown key 'abs_anchor_positons'"),
            std::string::npos);
  EXPECT_NE(error(base + "initial_pose: {p_IinG: [.inf, 0, 0], yaw_deg: 0}\n").find("initial_pose.p_IinG[0]' must be a finite number"),
            std::string::npos);
  EXPECT_NE(error(base + "pair_biases: [{ids: [100, 101], gamma: 0.1, sigma_gamma: -0.02}]\n")
                .find("key 'pair_biases[0].sigma_gamma' must be >= 0"),
            std::string::npos);
  EXPECT_NE(error(base + "pair_biases: [{ids: [100, 101], gama: 0.1}]\n").find("unknown key 'pair_biases[0].gama'"),
            std::string::npos);
  EXPECT_NE(error(base + "imu_id: one\n").find("key 'imu_id' must be an integer, got 'one'"), std::string::npos);
  EXPECT_NE(error(base + "baro_id: 105\n").find("key 'baro_id' = 105 is also a tag (rel_tag_positions.105)"),
            std::string::npos);
  EXPECT_NE(error(base + "imu_id: 101\n").find("key 'imu_id' = 101 is also an anchor (abs_anchor_positions.101)"),
            std::string::npos);
  EXPECT_NE(error(base + "imu_id: 7\nbaro_id: 7\n").find("same id 7"), std::string::npos);
  EXPECT_NE(error(base + "height_id: 105\n").find("key 'height_id' = 105 is also a tag"), std::string::npos);
  EXPECT_NE(error(base + "uwb_clock_id: 101\n").find("key 'uwb_clock_id' = 101 is also an anchor"), std::string::npos);
  EXPECT_NE(error(base + "imu_id: 9\nuwb_clock_id: 9\n").find("key 'imu_id' and key 'uwb_clock_id' are the same id 9"),
            std::string::npos);
  EXPECT_NE(error(base + "uwb_clock: {offset_s: 2}\n").find("key 'uwb_clock.offset_s'"), std::string::npos);
  EXPECT_NE(error(base + "uwb_clock: {sigma_s: -0.1}\n").find("key 'uwb_clock.sigma_s'"), std::string::npos);
  EXPECT_NE(error(base + "uwb_clock: {offset: 0.03}\n").find("unknown key 'uwb_clock.offset'"), std::string::npos);
  // A key given twice (issue 36): YAML readers differ on which wins; refused with both lines.
  EXPECT_NE(error("imu_id: 7\n" + base + "imu_id: 9\n").find("key 'imu_id' given twice (first at line 1)"),
            std::string::npos);
  EXPECT_NE(error(base + "baro:\n  p_IP: [0, 0, 0]\n  p_IP: [0, 0, 1]\n").find("key 'baro.p_IP' given twice"),
            std::string::npos);
  EXPECT_NE(error(base + "pair_biases: [{ids: [100, 101], gamma: 0.1, gamma: 0.2}]\n")
                .find("key 'pair_biases[0].gamma' given twice"),
            std::string::npos);
  EXPECT_NE(error(base + "imu_id: 3\nheight_id: 3\n").find("key 'imu_id' and key 'height_id' are the same id 3"),
            std::string::npos);
  EXPECT_NE(error(base + "height: {p_IH: [0, 0]}\n").find("height.p_IH"), std::string::npos);
  EXPECT_NE(error(base + "noise: {sigma_range: -0.1}\n").find("key 'noise.sigma_range' must be > 0"), std::string::npos);
  EXPECT_NE(error(base + "noise: {imu_acc_bias_sigma: 0}\n").find("key 'noise.imu_acc_bias_sigma' must be > 0"),
            std::string::npos);
  EXPECT_NE(error(base + "noise: {sigma_gamma: -0.1}\n").find("key 'noise.sigma_gamma' must be in [0, 10]"),
            std::string::npos);
  EXPECT_NE(error(base + "noise: {range_correlation_time: 100}\n").find("key 'noise.range_correlation_time' must be in [0, 60]"),
            std::string::npos);
  EXPECT_NE(error(base + "noise: {sigma_rnage: 0.1}\n").find("unknown key 'noise.sigma_rnage'"), std::string::npos);
  EXPECT_NE(error(base + "carried_height: {sigma_m: 0.3}\n").find("carried_height.height_m"), std::string::npos);
  EXPECT_NE(error(base + "carried_height: {height_m: -1}\n").find("key 'carried_height.height_m' must be a height"),
            std::string::npos);
  EXPECT_NE(error(base + "carried_height: {height_m: 1.2, sigma_m: 0}\n").find("key 'carried_height.sigma_m' must be > 0"),
            std::string::npos);
  EXPECT_NE(error(base + "carried_height: {height_m: 1.2, sigma: 0.3}\n").find("unknown key 'carried_height.sigma'"),
            std::string::npos);
  EXPECT_NE(error(base + "flight_volume: {min_m: [0, 0, 0]}\n").find("flight_volume.max_m"), std::string::npos);
  EXPECT_NE(error(base + "flight_volume: {min_m: [10, 10, 0], max_m: [15, 15, 3]}\n").find("does not hold known anchor 101"),
            std::string::npos);
  EXPECT_NE(error(base + "flight_volume: {min_m: [0, 0, 0], max_m: [5, 5, 0]}\n").find("key 'flight_volume' min_m must be below max_m"),
            std::string::npos);
  EXPECT_NE(error(base + "flight_volume: {min_m: [0, 0, 0], max_m: [5, .inf, 3]}\n").find("flight_volume"),
            std::string::npos);
  EXPECT_NE(error(base + "flight_volume: {min_m: [0, 0, 0], max_m: [5, 5, 3], margin: 1}\n").find("unknown key 'flight_volume.margin'"),
            std::string::npos);
  EXPECT_NE(error(base + "baro: {reference_pressure: 1e9}\n").find("key 'baro.reference_pressure'"), std::string::npos);
  EXPECT_NE(error("abs_anchor_positions: {4294967297: [0, 0, 0]}\n").find("'4294967297' is not a device id"),
            std::string::npos);
  EXPECT_NE(error(base + "abs_anchor_sigmas: {101: .nan}\n").find("abs_anchor_sigmas.101' must be a finite number"),
            std::string::npos);
  // Missing keys take their defaults; imu_id / baro_id left out and taken by a device move aside.
  EXPECT_EQ(error(base), "");
  const auto f = test::writeFile(d / "setup.yaml", "rel_tag_positions: {0: [0, 0, 0]}\nabs_anchor_positions: {1: [0, 0, 1], 2: [1, 0, 0]}\n"
                                                   "baro: {}\ninitial_pose: {p_IinG: [0, 0, 0], yaw_deg: 10}\n");
  const SystemSetup s = loadSetup(f);
  EXPECT_EQ(s.imu_id, 3);
  EXPECT_EQ(s.baro_id, 4);
  EXPECT_EQ(s.height_id, 5);  // its default 3 made way for the IMU
  EXPECT_EQ(s.uwb_clock_id, 6);  // its default 4 made way for the baro
  EXPECT_DOUBLE_EQ(s.uwb_clock.offset_s, 0.0);
  EXPECT_FALSE(s.uwb_clock.sigma_s);  // the estimator's option gives the prior
  ASSERT_TRUE(s.initial_pose);
  EXPECT_DOUBLE_EQ(s.initial_pose->sigma_p_m, InitialPose{}.sigma_p_m);
}

TEST(Truth, RoundTrip) {
  const test::TempDir d("truth");
  Truth t;
  t.anchor_positions[106] = {1, 2, 3};
  t.pair_biases.push_back({100, 106, -0.2, 0.995, 0.1});
  t.scalars["seed"] = 3;
  saveTruth(t, (d / "truth.yaml").string());
  const auto r = loadTruth((d / "truth.yaml").string());
  EXPECT_TRUE(r.anchor_positions.at(106).isApprox(Eigen::Vector3d(1, 2, 3)));
  ASSERT_EQ(r.pair_biases.size(), 1u);
  EXPECT_DOUBLE_EQ(r.pair_biases[0].beta, 0.995);
  EXPECT_DOUBLE_EQ(r.scalars.at("seed"), 3);
}

TEST(Truth, FrameOfTheGroundTruthRoundTripsAndDefaultsToTheWorldFrame) {
  const test::TempDir d("truth_frame");
  Truth t;
  t.truth_frame = "vive/reference";
  t.align_required = true;
  saveTruth(t, (d / "truth.yaml").string());
  const auto r = loadTruth((d / "truth.yaml").string());
  EXPECT_EQ(r.truth_frame, "vive/reference");
  EXPECT_TRUE(r.align_required);
  // A simulated truth.yaml (no keys): the world frame, no alignment.
  const auto plain = loadTruth(test::writeFile(d / "plain.yaml", "anchor_positions: {101: [1, 2, 3]}\n"));
  EXPECT_TRUE(plain.truth_frame.empty());
  EXPECT_FALSE(plain.align_required);
}

TEST(Truth, AlignRequiredMustBeABoolean) {
  const test::TempDir d("truth_frame_bad");
  const auto f = test::writeFile(d / "truth.yaml", "truth_frame: vive\nalign_required: maybe\n");
  try {
    loadTruth(f);
    FAIL() << "no exception";
  } catch (const std::runtime_error& ex) {
    EXPECT_NE(std::string(ex.what()).find("align_required"), std::string::npos) << ex.what();
    EXPECT_NE(std::string(ex.what()).find(f), std::string::npos) << ex.what();
  }
}
