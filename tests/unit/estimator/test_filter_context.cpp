/// FilterContext (estimator/node/filter_context.h): a copy is independent of its original (what a
/// rewind relies on), and replaceImu puts the new IMU block in while every other instance keeps its
/// mean and its kind's kept covariance, cross-covariances dropped, the per-frame readings restarted.
#include <gtest/gtest.h>

#include "estimator/filter/strategy_factory.h"
#include "estimator/node/filter_context.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

Timestamp at(double s) { return Timestamp::fromSec(s); }

constexpr SensorId kImu = 1, kBaro = 2, kAnchor = 106;

/// A centralized filter at t = 1 s with a baro bias (σ 0.1 m) and an anchor (σ 0.3 m), correlated
/// with the pose by one update.
FilterContext smallContext(const EstimatorOptions& o) {
  FilterContext c;
  c.filter = makeStrategy(o);
  ImuState x;
  x.p_IinG = {1.0, 2.0, 3.0};
  c.filter->reset(kImu, x, ImuMatrix::Identity() * 0.25, at(1.0));
  c.filter->addInstance<BaroBiasKind>(kBaro, 0.4, Eigen::MatrixXd::Constant(1, 1, 0.01));
  c.filter->addInstance<AnchorKind>(kAnchor, AnchorState{Eigen::Vector3d(5.0, 0.0, 2.0)},
                                    Eigen::Matrix3d::Identity() * 0.09);
  // One update of the anchor's x against the pose's x correlates them.
  Linearization lin;
  lin.residual = Eigen::VectorXd::Constant(1, 0.1);
  lin.R = Eigen::MatrixXd::Constant(1, 1, 0.01);
  Eigen::MatrixXd H_imu = Eigen::MatrixXd::Zero(1, ImuErr::kDim), H_anchor = Eigen::MatrixXd::Zero(1, 3);
  H_imu(0, ImuErr::kP) = -1.0;
  H_anchor(0, 0) = 1.0;
  lin.blocks = {{kImu, H_imu}, {kAnchor, H_anchor}};
  c.filter->update(lin, 0.0);
  ImuSample s;
  s.t = at(1.0);
  c.last_imu = s;
  c.prev_imu = s;
  c.last_zupt = at(0.9);
  c.rest_rate.add(Eigen::Vector3d(0.01, 0.0, 0.0), 0.1, 1.0);
  c.mean_reading = ImuReading{};
  return c;
}

}  // namespace

TEST(FilterContext, ACopyDoesNotChangeWithItsOriginal) {
  const EstimatorOptions o;
  FilterContext c = smallContext(o);
  const FilterContext before = c.copy();
  const double x0 = c.filter->state().imu.p_IinG.x();
  // Move the original's pose: the copy (a rewind's snapshot) must not see it.
  ImuState x = c.filter->state().imu;
  x.p_IinG.x() += 10.0;
  c.replaceImu(x, ImuMatrix::Identity(), at(1.0), *c.last_imu, o, kImu, -1.0);
  EXPECT_DOUBLE_EQ(before.filter->state().imu.p_IinG.x(), x0);
  EXPECT_DOUBLE_EQ(c.filter->state().imu.p_IinG.x(), x0 + 10.0);
  EXPECT_EQ(before.network, c.network);  // shared, immutable
  EXPECT_DOUBLE_EQ(before.rest_rate.span(), 0.1);
}

TEST(FilterContext, ARewindRestoresEachPairsPreviousRange) {
  // The R inflation of correlated range errors depends on the pair's previous range: a rewind to
  // a copy must see the history as it was then, not the ranges processed after it.
  const EstimatorOptions o;
  FilterContext c = smallContext(o);
  c.range_errors = RangeErrorCorrelation(0.1);
  c.range_errors.noteRange(1001, 4, at(1.0));
  const FilterContext before = c.copy();
  c.range_errors.noteRange(1001, 4, at(1.05));
  EXPECT_NEAR(before.range_errors.inflation(1001, 4, at(1.1)), c.range_errors.inflation(1001, 4, at(1.15)), 1e-12);
  EXPECT_GT(c.range_errors.inflation(1001, 4, at(1.1)), before.range_errors.inflation(1001, 4, at(1.1)));
}

TEST(FilterContext, ReplaceImuKeepsTheOtherInstancesAndRestartsTheReadings) {
  EstimatorOptions o;
  o.baro.init_bias_sigma_m = 1.0;
  FilterContext c = smallContext(o);
  const Eigen::Vector3d anchor_before = c.filter->state().values<AnchorKind>().at(kAnchor).p_AinG;
  const Eigen::MatrixXd P_anchor_before = c.filter->covariance(kAnchor, kAnchor);
  ASSERT_FALSE(c.filter->covariance(kImu, kAnchor).isZero()) << "the update should have correlated them";
  ImuState x;
  x.p_IinG = {-1.0, 0.0, 1.5};
  ImuSample last;
  last.t = at(2.0);
  c.replaceImu(x, ImuMatrix::Identity() * 4.0, at(2.0), last, o, kImu, -1.0);
  const FusionStrategy& f = *c.filter;
  EXPECT_DOUBLE_EQ(f.state().t.sec(), 2.0);
  EXPECT_TRUE(f.state().imu.p_IinG.isApprox(x.p_IinG));
  EXPECT_DOUBLE_EQ(f.covariance(kImu, kImu)(0, 0), 4.0);
  // Means kept; the anchor's marginal covariance kept, the baro bias widened to its init σ (BaroBiasKind).
  EXPECT_DOUBLE_EQ(f.state().values<BaroBiasKind>().at(kBaro), 0.4);
  EXPECT_TRUE(f.state().values<AnchorKind>().at(kAnchor).p_AinG.isApprox(anchor_before));
  EXPECT_TRUE(f.covariance(kAnchor, kAnchor).isApprox(P_anchor_before));
  EXPECT_DOUBLE_EQ(f.covariance(kBaro, kBaro)(0, 0), 1.0);
  // Cross-covariances restart from zero.
  EXPECT_TRUE(f.covariance(kImu, kAnchor).isZero());
  // What was in the old attitude and time line restarts.
  EXPECT_FALSE(c.mean_reading);
  EXPECT_FALSE(c.prev_imu);
  EXPECT_DOUBLE_EQ(c.last_imu->t.sec(), 2.0);
  EXPECT_DOUBLE_EQ(c.last_zupt.sec(), 2.0);
  EXPECT_DOUBLE_EQ(c.rest_rate.span(), 0.0);
}
