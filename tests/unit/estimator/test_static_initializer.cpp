/// StaticInitializer: the range fit of a body at rest, its refusal of a mirrored height and the
/// height prior from the barometer (setup reference pressure) or the setup's carried height.
#include <gtest/gtest.h>

#include <cmath>

#include "common/atmosphere.h"
#include "estimator/init/static_initializer.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

/// Three known anchors in a horizontal plane at `anchor_z_m`, two tags, the body at rest at
/// p_IinG (level, yaw 30°): noise-free ranges, IMU and (optionally) baro for up to 2 s.
struct RestScene {
  SystemSetup setup;
  Eigen::Vector3d p_IinG;
  double yaw_rad = 30.0 * M_PI / 180.0;
  RestScene(double anchor_z_m, double body_z_m) : p_IinG(1.0, 0.5, body_z_m) {
    setup.rel_tag_positions[100] = {0.2, 0.0, 0.0};
    setup.rel_tag_positions[105] = {-0.2, 0.1, 0.0};
    setup.abs_anchor_positions[101] = {-4.0, -3.0, anchor_z_m};
    setup.abs_anchor_positions[102] = {4.0, -3.0, anchor_z_m};
    setup.abs_anchor_positions[103] = {0.5, 4.0, anchor_z_m};
  }
  std::optional<InitialBelief> run(StaticInitializer& init, bool baro) const {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    std::optional<InitialBelief> b;
    for (int k = 0; k <= 400 && !b; ++k) {
      const Timestamp t = Timestamp::fromSec(0.005 * k);
      init.addStillness(true);
      init.addImu({t, Eigen::Vector3d(0, 0, 9.81), Eigen::Vector3d::Zero()});
      if (baro && k % 4 == 0)
        init.addBaro({t, atmosphere::pressureFromHeight((p_IinG + R * setup.baro_p_IP).z(),
                                                        *setup.baro_reference_pressure_pa)});
      if (k % 10 == 0)
        for (const auto& [tag, p_T] : setup.rel_tag_positions)
          for (const auto& [anchor, p_A] : setup.abs_anchor_positions) {
            RangeSample r;
            r.t = t;
            r.id_initiator = tag;
            r.id_responder = anchor;
            r.range_m = r.range_corr_m = (p_A - p_IinG - R * p_T).norm();
            init.addRange(r);
          }
      b = init.tryInitialize();
    }
    return b;
  }
};

EstimatorOptions restOptions() {
  EstimatorOptions o;
  o.init.duration_s = 1.0;
  return o;
}

}  // namespace

TEST(StaticInitializer, CoplanarAnchorsWithoutAHeightPriorAreRefusedNotMirrored) {
  for (const double body_z : {2.4, -0.4, 4.5}) {  // above, below (its mirror image), far above
    const RestScene scene(1.0, body_z);
    StaticInitializer init(restOptions(), scene.setup);
    EXPECT_FALSE(scene.run(init, false)) << "body at z = " << body_z;
    EXPECT_NE(init.waitingFor().find("fit the landed ranges alike"), std::string::npos) << init.waitingFor();
  }
}

TEST(StaticInitializer, BaroWithAReferencePressurePicksTheTrueSideOfTheAnchorPlane) {
  // The baro's bias prior (baro.init_bias_sigma_m, 1 m) outweighs a mirror image 7 m away.
  RestScene scene(1.0, 4.5);
  scene.setup.baro_reference_pressure_pa = 97000.0;
  scene.setup.baro_p_IP = {0.0, 0.0, 0.05};
  StaticInitializer init(restOptions(), scene.setup);
  const auto b = scene.run(init, true);
  ASSERT_TRUE(b) << init.waitingFor();
  EXPECT_TRUE(b->from_ranges);
  EXPECT_LT((b->imu.p_IinG - scene.p_IinG).norm(), 0.01);
  // A mirror image only 2.8 m away is within that prior's reach: still refused, not guessed.
  RestScene near(1.0, 2.4);
  near.setup.baro_reference_pressure_pa = 97000.0;
  StaticInitializer init_near(restOptions(), near.setup);
  EXPECT_FALSE(near.run(init_near, true));
}

TEST(StaticInitializer, CarriedHeightPicksTheTrueSideOfTheAnchorPlane) {
  // A hand-held rig at 1.2 m under anchors at 2.5 m; its mirror image at 3.8 m.
  RestScene scene(2.5, 1.2);
  scene.setup.carried_height = CarriedHeight{1.2, 0.3};
  StaticInitializer init(restOptions(), scene.setup);
  const auto b = scene.run(init, false);
  ASSERT_TRUE(b) << init.waitingFor();
  EXPECT_LT((b->imu.p_IinG - scene.p_IinG).norm(), 0.01);
  // Turned off in the options: back to ranges alone, which cannot tell.
  EstimatorOptions off = restOptions();
  off.carried_height.enabled = false;
  StaticInitializer init_off(off, scene.setup);
  EXPECT_FALSE(scene.run(init_off, false));
}

TEST(StaticInitializer, TheFlightVolumeRulesOutTheMirrorImageBehindTheAnchorPlane) {
  // Anchors on the ceiling at 3 m of a hall 0–3.2 m high, the body landed at 1.0 m: its mirror
  // image at 5.0 m is outside the hall, so the fit is no longer ambiguous.
  RestScene scene(3.0, 1.0);
  scene.setup.flight_volume = FlightVolume{Eigen::Vector3d(-5, -5, 0), Eigen::Vector3d(5, 5, 3.2)};
  StaticInitializer init(restOptions(), scene.setup);
  const auto b = scene.run(init, false);
  ASSERT_TRUE(b) << init.waitingFor();
  EXPECT_LT((b->imu.p_IinG - scene.p_IinG).norm(), 0.01);
  // Turned off in the options: the ranges alone cannot tell.
  EstimatorOptions off = restOptions();
  off.flight_volume.enabled = false;
  StaticInitializer init_off(off, scene.setup);
  EXPECT_FALSE(scene.run(init_off, false));
  EXPECT_NE(init_off.waitingFor().find("fit the landed ranges alike"), std::string::npos) << init_off.waitingFor();
  // A volume that holds neither image: refused, saying so.
  scene.setup.flight_volume = FlightVolume{Eigen::Vector3d(10, 10, 0), Eigen::Vector3d(12, 12, 3.2)};
  StaticInitializer init_far(restOptions(), scene.setup);
  EXPECT_FALSE(scene.run(init_far, false));
  EXPECT_NE(init_far.waitingFor().find("outside the flight volume"), std::string::npos) << init_far.waitingFor();
}
