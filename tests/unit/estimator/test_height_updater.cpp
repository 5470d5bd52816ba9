/// HeightUpdater (estimator/height/height_updater.h): readings refused by name (below the minimum
/// range, the body tilted beyond max_tilt_deg unless carried, height_id an estimated anchor's), the
/// bias instance added once with the alignment's prior or N(0, init_bias_sigma²), the update.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "estimator/filter/strategy_factory.h"
#include "estimator/height/height_updater.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

Timestamp at(double s) { return Timestamp::fromSec(s); }

constexpr SensorId kHeight = 3;

HeightOptions heightOptions() {
  HeightOptions o;
  o.min_range_m = 0.3;
  o.max_tilt_deg = 30.0;
  o.init_bias_sigma_m = 0.3;
  o.sigma_m = 0.05;
  return o;
}

/// A filter at z = 1.5 m (σ 1 m), rolled by `roll_deg`.
std::unique_ptr<FusionStrategy> filterRolled(double roll_deg) {
  auto f = makeStrategy(EstimatorOptions{});
  ImuState x;
  x.p_IinG = {0.0, 0.0, 1.5};
  x.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(roll_deg * M_PI / 180.0, Eigen::Vector3d::UnitX()));
  f->reset(1, x, ImuMatrix::Identity(), at(2.0));
  return f;
}

}  // namespace

TEST(HeightUpdater, RefusalsByName) {
  const HeightUpdater h(heightOptions(), kHeight, Eigen::Vector3d::Zero(), false);
  auto level = filterRolled(0.0);
  EXPECT_EQ(h.refusal(*level, {at(2.0), 1.2}), "");
  EXPECT_EQ(h.refusal(*level, {at(2.0), 0.3}), "");  // at the minimum
  EXPECT_EQ(h.refusal(*level, {at(2.0), 0.29}), "height_below_min_range");
  EXPECT_EQ(h.refusal(*filterRolled(29.0), {at(2.0), 1.2}), "");
  EXPECT_EQ(h.refusal(*filterRolled(31.0), {at(2.0), 1.2}), "height_tilted");
  EXPECT_EQ(h.refusal(*filterRolled(-45.0), {at(2.0), 1.2}), "height_tilted");
  // The minimum range comes first.
  EXPECT_EQ(h.refusal(*filterRolled(45.0), {at(2.0), 0.1}), "height_below_min_range");
  // An estimated anchor with the sensor's id: its readings are not heights.
  level->addInstance<AnchorKind>(kHeight, AnchorState(Eigen::Vector3d(1, 2, 3)), Eigen::Matrix3d::Identity());
  EXPECT_EQ(h.refusal(*level, {at(2.0), 1.2}), "height_id_is_an_anchor");
}

TEST(HeightUpdater, ACarriedHeightIsNotRefusedForTilt) {
  const HeightUpdater carried(heightOptions(), kHeight, Eigen::Vector3d::Zero(), true);
  EXPECT_TRUE(carried.carried());
  EXPECT_EQ(carried.refusal(*filterRolled(60.0), {at(2.0), 1.2}), "");
  EXPECT_EQ(carried.refusal(*filterRolled(60.0), {at(2.0), 0.2}), "height_below_min_range");
  EXPECT_STREQ(carried.typeName(), "carried_height");
  const HeightUpdater sensor(heightOptions(), kHeight, Eigen::Vector3d::Zero(), false);
  EXPECT_FALSE(sensor.carried());
  EXPECT_STREQ(sensor.typeName(), "height");
}

TEST(HeightUpdater, TheBiasInstanceIsAddedOnceWithItsPrior) {
  HeightUpdater h(heightOptions(), kHeight, Eigen::Vector3d::Zero(), false);
  auto f = filterRolled(0.0);
  ASSERT_EQ(f->state().values<HeightBiasKind>().count(kHeight), 0u);
  h.ensureBiasState(*f, at(2.0), false);
  ASSERT_EQ(f->state().values<HeightBiasKind>().count(kHeight), 1u);
  EXPECT_DOUBLE_EQ(f->state().values<HeightBiasKind>().at(kHeight), 0.0);
  EXPECT_NEAR(f->covariance(kHeight, kHeight)(0, 0), 0.09, 1e-15);  // N(0, 0.3²)
  // Present: not replaced, whatever the prior says now.
  h.setBiasPrior(std::make_pair(0.12, 0.0025));
  h.ensureBiasState(*f, at(2.1), true);
  EXPECT_DOUBLE_EQ(f->state().values<HeightBiasKind>().at(kHeight), 0.0);
  EXPECT_NEAR(f->covariance(kHeight, kHeight)(0, 0), 0.09, 1e-15);
  EXPECT_EQ(f->layout().blocks().size(), 2u);  // IMU and the one bias
  // A new filter takes the alignment's estimate as the prior …
  auto g = filterRolled(0.0);
  h.ensureBiasState(*g, at(2.0), true);
  EXPECT_DOUBLE_EQ(g->state().values<HeightBiasKind>().at(kHeight), 0.12);
  EXPECT_NEAR(g->covariance(kHeight, kHeight)(0, 0), 0.0025, 1e-15);
  // … and N(0, init_bias_sigma²) again once the prior is gone.
  h.setBiasPrior(std::nullopt);
  auto k = filterRolled(0.0);
  h.ensureBiasState(*k, at(2.0), false);
  EXPECT_DOUBLE_EQ(k->state().values<HeightBiasKind>().at(kHeight), 0.0);
  EXPECT_NEAR(k->covariance(kHeight, kHeight)(0, 0), 0.09, 1e-15);
}

TEST(HeightUpdater, AReadingPullsTheHeightTowardIt) {
  const HeightUpdater h(heightOptions(), kHeight, Eigen::Vector3d::Zero(), false);
  auto f = filterRolled(0.0);
  h.ensureBiasState(*f, at(2.0), false);
  const UpdateResult r = h.update(*f, {at(2.0), 1.2});
  EXPECT_TRUE(r.accepted);
  // Level, no lever: h = z + b with H = [1, 1], S = 1 + 0.09 + 0.05²; ν = −0.3.
  const double S = 1.0 + 0.09 + 0.0025;
  EXPECT_NEAR(r.nis, 0.09 / S, 1e-9);
  EXPECT_NEAR(f->state().imu.p_IinG.z(), 1.5 - 0.3 / S, 1e-9);
  EXPECT_NEAR(f->state().values<HeightBiasKind>().at(kHeight), -0.3 * 0.09 / S, 1e-9);
}
