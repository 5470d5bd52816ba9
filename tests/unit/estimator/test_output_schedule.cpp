/// OutputSchedule (estimator/node/output_schedule.h): the POSE rate on IMU steps, the fixed period
/// of ANCHORS and ESTIMATOR_STATUS restarted after a pause, the resets; poseOf / anchorsOf of a
/// small filter (values, covariance blocks, ids sorted).
#include <gtest/gtest.h>

#include "estimator/filter/strategy_factory.h"
#include "estimator/node/output_schedule.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

Timestamp at(double s) { return Timestamp::fromSec(s); }

}  // namespace

TEST(OutputSchedule, PoseIsDueOncePerPeriodOfItsRate) {
  OutputSchedule o(10.0, 1.0, 1.0);
  EXPECT_TRUE(o.poseDue(at(5.0)));    // the first one
  EXPECT_FALSE(o.poseDue(at(5.05)));
  EXPECT_FALSE(o.poseDue(at(5.099)));  // 1 ms short of the period
  EXPECT_TRUE(o.poseDue(at(5.1)));    // exactly one period later
  // Late by 0.03 s: the next one is a full period after this one (5.33), not on a 5.0 + k·0.1 grid.
  EXPECT_TRUE(o.poseDue(at(5.23)));
  EXPECT_FALSE(o.poseDue(at(5.3)));
  EXPECT_TRUE(o.poseDue(at(5.33)));
}

TEST(OutputSchedule, PoseRateZeroOrNegativePublishesEveryStep) {
  for (const double rate : {0.0, -1.0}) {
    OutputSchedule o(rate, 1.0, 1.0);
    for (int k = 0; k < 5; ++k) EXPECT_TRUE(o.poseDue(at(1.0 + 0.005 * k))) << "rate " << rate << " step " << k;
    EXPECT_TRUE(o.poseDue(at(1.02)));  // even at the same time again
  }
}

TEST(OutputSchedule, AnchorsAtAFixedPeriodFromTheFirstOne) {
  OutputSchedule o(0.0, 1.0, 1.0);
  EXPECT_TRUE(o.anchorsDue(at(10.0)));
  EXPECT_FALSE(o.anchorsDue(at(10.5)));
  EXPECT_FALSE(o.anchorsDue(at(10.999)));
  EXPECT_TRUE(o.anchorsDue(at(11.0)));
  // Late by 0.3 s: the next one stays on the grid (13.0), not one period after this one (13.3).
  EXPECT_TRUE(o.anchorsDue(at(12.3)));
  EXPECT_FALSE(o.anchorsDue(at(12.9)));
  EXPECT_TRUE(o.anchorsDue(at(13.0)));
}

TEST(OutputSchedule, APauseLongerThanAPeriodRestartsThePeriod) {
  OutputSchedule o(0.0, 1.0, 2.0);
  EXPECT_TRUE(o.statusDue(at(0.0)));  // next 0.5
  EXPECT_TRUE(o.statusDue(at(0.5)));  // next 1.0
  // A pause of 4 s: the period starts over at 5.0 (next 5.5), it does not catch up on the grid.
  EXPECT_TRUE(o.statusDue(at(5.0)));
  EXPECT_FALSE(o.statusDue(at(5.2)));
  EXPECT_FALSE(o.statusDue(at(5.49)));
  EXPECT_TRUE(o.statusDue(at(5.5)));
  // Status and anchors keep their own schedules.
  EXPECT_TRUE(o.anchorsDue(at(5.6)));
  EXPECT_FALSE(o.anchorsDue(at(6.0)));
  EXPECT_TRUE(o.statusDue(at(6.0)));
}

TEST(OutputSchedule, ResetsStartTheSchedulesOver) {
  OutputSchedule o(10.0, 1.0, 1.0);
  ASSERT_TRUE(o.poseDue(at(20.0)));
  ASSERT_TRUE(o.anchorsDue(at(20.0)));
  ASSERT_TRUE(o.statusDue(at(20.0)));
  // resetPose: only the pose's rate.
  o.resetPose();
  EXPECT_TRUE(o.poseDue(at(20.01)));
  EXPECT_FALSE(o.anchorsDue(at(20.01)));
  EXPECT_FALSE(o.statusDue(at(20.01)));
  // resetAll after the clock jumped back to 3 s: everything due at once, also the periods.
  o.resetAll();
  EXPECT_TRUE(o.poseDue(at(3.0)));
  EXPECT_TRUE(o.anchorsDue(at(3.0)));
  EXPECT_TRUE(o.statusDue(at(3.0)));
  EXPECT_FALSE(o.anchorsDue(at(3.5)));
  EXPECT_FALSE(o.poseDue(at(3.05)));
}

TEST(OutputSchedule, PoseAndAnchorsOfASmallFilter) {
  EstimatorOptions opt;
  auto f = makeStrategy(opt);
  ImuState x;
  x.p_IinG = {1.0, -2.0, 3.0};
  x.v_IinG = {0.1, 0.2, -0.3};
  x.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()));
  x.bias_gyro_rad_s = {0.001, -0.002, 0.003};
  x.bias_acc_m_s2 = {0.01, 0.02, -0.03};
  ImuVector sd;
  for (int i = 0; i < ImuErr::kDim; ++i) sd(i) = 0.1 * (i + 1);
  const ImuMatrix P = sd.cwiseProduct(sd).asDiagonal();
  f->reset(1, x, P, at(7.5));
  // Estimated anchors added out of id order; exact ones from the setup.
  const Eigen::Matrix3d C107 = Eigen::Vector3d(0.04, 0.09, 0.16).asDiagonal();
  const Eigen::Matrix3d C106 = Eigen::Matrix3d::Identity() * 0.25;
  f->addInstance<AnchorKind>(107, AnchorState(Eigen::Vector3d(7, 0, 1)), C107);
  f->addInstance<AnchorKind>(106, AnchorState(Eigen::Vector3d(6, 0, 1)), C106);
  SystemSetup setup;
  setup.abs_anchor_positions = {{104, {4, 0, 2}}, {101, {1, 0, 2}}, {102, {2, 0, 2}}};
  const UwbNetwork network(setup, 0.15);

  const PoseEstimate e = poseOf(*f);
  EXPECT_EQ(e.t, at(7.5));
  EXPECT_EQ(e.p_IinG, x.p_IinG);
  EXPECT_EQ(e.v_IinG, x.v_IinG);
  EXPECT_TRUE(e.q_ItoG.isApprox(x.q_ItoG, 1e-15));
  EXPECT_EQ(e.bias_gyro_rad_s, x.bias_gyro_rad_s);
  EXPECT_EQ(e.bias_acc_m_s2, x.bias_acc_m_s2);
  // Each block from its own rows: position 0.1² … 0.3², velocity 0.4² …, attitude 0.7² ….
  EXPECT_TRUE(e.cov_p_m2.isApprox(P.block<3, 3>(ImuErr::kP, ImuErr::kP), 1e-12));
  EXPECT_TRUE(e.cov_v.isApprox(P.block<3, 3>(ImuErr::kV, ImuErr::kV), 1e-12));
  EXPECT_TRUE(e.cov_theta_rad2.isApprox(P.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta), 1e-12));
  EXPECT_NEAR(e.cov_v(0, 0), 0.16, 1e-12);

  const auto anchors = anchorsOf(*f, network);
  ASSERT_EQ(anchors.size(), 5u);
  const std::vector<SensorId> ids = {101, 102, 104, 106, 107};
  for (size_t i = 0; i < ids.size(); ++i) {
    EXPECT_EQ(anchors[i].id, ids[i]);
    EXPECT_EQ(anchors[i].t, at(7.5));
  }
  EXPECT_EQ(anchors[2].p_AinG, Eigen::Vector3d(4, 0, 2));
  EXPECT_TRUE(anchors[0].cov_p_m2.isZero(0.0));  // exact anchors: zero covariance
  EXPECT_EQ(anchors[3].p_AinG, Eigen::Vector3d(6, 0, 1));
  EXPECT_TRUE(anchors[3].cov_p_m2.isApprox(C106, 1e-12));
  EXPECT_TRUE(anchors[4].cov_p_m2.isApprox(C107, 1e-12));
}
