/// RecoveryPolicy (estimator/health/recovery_policy.h): the evaluation throttle, when an alignment
/// is due (lost, degraded with ranges that do not fit, within the window after a long IMU gap, at
/// most every retry_s) and the χ²(4) disagreement of two poses, checked against numbers by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "estimator/health/recovery_policy.h"

using namespace meshnav;
using namespace meshnav::estimator;

namespace {

Timestamp at(double s) { return Timestamp::fromSec(s); }

constexpr double kWindow_s = 12.0;  // init.motion_window_s

RecoveryOptions recovery() {
  RecoveryOptions o;
  o.enabled = true;
  o.retry_s = 1.0;
  o.degraded_disagreement_chi2 = 23.5;
  o.after_gap_check_min_s = 1.0;
  return o;
}

/// A level pose at `p` with heading `yaw`.
ImuState pose(const Eigen::Vector3d& p, double yaw) {
  ImuState x;
  x.p_IinG = p;
  x.q_ItoG = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  return x;
}
/// A diagonal IMU covariance: position variances `var_p`, attitude 0.01 rad² about x and y and
/// `var_yaw` about z (for a level pose, the yaw variance).
ImuMatrix cov(const Eigen::Vector3d& var_p, double var_yaw) {
  ImuMatrix P = ImuMatrix::Identity();
  P.block<3, 3>(ImuErr::kP, ImuErr::kP) = var_p.asDiagonal();
  P.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) = Eigen::Vector3d(0.01, 0.01, var_yaw).asDiagonal();
  return P;
}

}  // namespace

TEST(RecoveryPolicy, HealthIsEvaluatedAtMostEveryPeriod) {
  RecoveryPolicy r(recovery(), kWindow_s);
  ASSERT_DOUBLE_EQ(RecoveryPolicy::kEvaluationPeriod_s, 0.1);
  EXPECT_TRUE(r.evaluationDue(at(1.0)));
  EXPECT_FALSE(r.evaluationDue(at(1.05)));
  EXPECT_FALSE(r.evaluationDue(at(1.0999)));
  // One period after the last evaluation (1 µs past it: exactly 0.1 s is 0.09999999999999999 s
  // as Duration::sec() computes it, and the comparison has no tolerance).
  EXPECT_TRUE(r.evaluationDue(at(1.100001)));
  EXPECT_FALSE(r.evaluationDue(at(1.15)));  // a refusal is not an evaluation: 1.2 is due
  EXPECT_TRUE(r.evaluationDue(at(1.200002)));
  // reset() keeps the evaluation time; resetAll() (clock back) forgets it.
  r.reset();
  EXPECT_FALSE(r.evaluationDue(at(1.25)));
  r.resetAll();
  EXPECT_TRUE(r.evaluationDue(at(0.3)));
}

TEST(RecoveryPolicy, LostIsDueAtMostEveryRetry) {
  RecoveryPolicy r(recovery(), kWindow_s);
  EXPECT_TRUE(r.alignmentDue(at(10.0), Health::Lost, false));
  EXPECT_FALSE(r.alignmentDue(at(10.5), Health::Lost, false));
  EXPECT_FALSE(r.alignmentDue(at(10.999), Health::Lost, false));
  EXPECT_TRUE(r.alignmentDue(at(11.0), Health::Lost, false));
  // Healthy: never, however long after the last try.
  EXPECT_FALSE(r.alignmentDue(at(20.0), Health::Ok, false));
  EXPECT_FALSE(r.alignmentDue(at(21.0), Health::Initializing, false));
  // A call that wants nothing is no try: lost right after it is due.
  EXPECT_TRUE(r.alignmentDue(at(21.1), Health::Lost, false));
  // reset() forgets the retry time.
  r.reset();
  EXPECT_TRUE(r.alignmentDue(at(21.2), Health::Lost, false));
}

TEST(RecoveryPolicy, DegradedIsDueOnlyWhenTheAcceptedRangesDoNotFit) {
  RecoveryPolicy r(recovery(), kWindow_s);
  EXPECT_FALSE(r.alignmentDue(at(5.0), Health::Degraded, true));  // NLOS outliers gated: trust the filter
  EXPECT_TRUE(r.alignmentDue(at(5.1), Health::Degraded, false));
  EXPECT_FALSE(r.alignmentDue(at(5.5), Health::Degraded, false));  // retry_s
  EXPECT_TRUE(r.alignmentDue(at(6.1), Health::Degraded, false));
  // With the comparison off (bound 0) degraded never asks; lost still does.
  RecoveryOptions off = recovery();
  off.degraded_disagreement_chi2 = 0.0;
  RecoveryPolicy r_off(off, kWindow_s);
  EXPECT_FALSE(r_off.alignmentDue(at(5.0), Health::Degraded, false));
  EXPECT_TRUE(r_off.alignmentDue(at(5.1), Health::Lost, false));
}

TEST(RecoveryPolicy, AfterALongImuGapDueWithinTheWindowOnly) {
  RecoveryPolicy r(recovery(), kWindow_s);
  EXPECT_FALSE(r.afterGap(at(30.0)));
  r.noteImuGap(at(30.0), 1.0);  // exactly after_gap_check_min_s
  EXPECT_TRUE(r.afterGap(at(30.0)));
  EXPECT_TRUE(r.afterGap(at(42.0)));  // the window's end included
  EXPECT_FALSE(r.afterGap(at(42.001)));
  EXPECT_TRUE(r.alignmentDue(at(31.0), Health::Ok, true));
  EXPECT_FALSE(r.alignmentDue(at(31.5), Health::Ok, true));  // retry_s holds here too
  EXPECT_TRUE(r.alignmentDue(at(41.9), Health::Ok, true));
  EXPECT_FALSE(r.alignmentDue(at(43.0), Health::Ok, true));  // after the window
  // The replay node of a re-run takes the live window.
  RecoveryPolicy replay(recovery(), kWindow_s);
  replay.copyGapWindowFrom(r);
  EXPECT_TRUE(replay.afterGap(at(35.0)));
  // reset() forgets the window.
  r.reset();
  EXPECT_FALSE(r.afterGap(at(35.0)));
}

TEST(RecoveryPolicy, AShortGapOrDisabledRecoveryAsksNothing) {
  RecoveryPolicy r(recovery(), kWindow_s);
  r.noteImuGap(at(30.0), 0.99);
  EXPECT_FALSE(r.afterGap(at(30.5)));
  EXPECT_FALSE(r.alignmentDue(at(30.5), Health::Ok, true));

  RecoveryOptions no_gap = recovery();
  no_gap.after_gap_check_min_s = 0.0;  // off, however long the gap
  RecoveryPolicy r_no_gap(no_gap, kWindow_s);
  r_no_gap.noteImuGap(at(30.0), 100.0);
  EXPECT_FALSE(r_no_gap.afterGap(at(30.5)));

  RecoveryOptions disabled = recovery();
  disabled.enabled = false;
  RecoveryPolicy r_off(disabled, kWindow_s);
  r_off.noteImuGap(at(30.0), 5.0);
  for (double t = 30.0; t < 40.0; t += 1.5) {
    EXPECT_FALSE(r_off.alignmentDue(at(t), Health::Lost, false)) << t;
    EXPECT_FALSE(r_off.alignmentDue(at(t + 0.1), Health::Degraded, false)) << t;
  }
}

TEST(RecoveryPolicy, DisagreementOfTwoPosesIsTheirChiSquare) {
  const ImuState x = pose({1.0, 2.0, 3.0}, 0.3);
  const ImuMatrix Pf = cov({0.04, 0.09, 0.01}, 0.0004);
  AlignmentResult a;
  a.imu = x;
  a.cov = cov({0.05, 0.16, 0.03}, 0.0005);
  EXPECT_NEAR(RecoveryPolicy::disagreement(x, Pf, a), 0.0, 1e-12);

  // S = P_f + P_a: σ_x = √0.09 = 0.3, σ_y = √0.25 = 0.5, σ_z = √0.04 = 0.2, σ_ψ = √0.0009 = 0.03.
  a.imu.p_IinG = x.p_IinG + Eigen::Vector3d(0.6, 0.0, 0.0);  // 2σ along x
  EXPECT_NEAR(RecoveryPolicy::disagreement(x, Pf, a), 4.0, 1e-9);
  a.imu.p_IinG = x.p_IinG + Eigen::Vector3d(0.0, -1.5, 0.0);  // 3σ along y
  EXPECT_NEAR(RecoveryPolicy::disagreement(x, Pf, a), 9.0, 1e-9);
  a.imu.p_IinG = x.p_IinG + Eigen::Vector3d(0.6, -1.5, 0.2);  // 2σ, 3σ, 1σ
  EXPECT_NEAR(RecoveryPolicy::disagreement(x, Pf, a), 4.0 + 9.0 + 1.0, 1e-9);
  a.imu = pose(x.p_IinG, 0.3 + 0.12);  // 4σ in yaw
  EXPECT_NEAR(RecoveryPolicy::disagreement(x, Pf, a), 16.0, 1e-6);
}

TEST(RecoveryPolicy, YawDifferenceWrapsAtPi) {
  // 3.1 rad and −3.1 rad are 2π − 6.2 = 0.0832 rad apart, not 6.2 rad.
  const ImuState x = pose({0, 0, 1}, 3.1);
  const ImuMatrix P = cov({0.04, 0.04, 0.04}, 0.0004);
  AlignmentResult a;
  a.imu = pose({0, 0, 1}, -3.1);
  a.cov = cov({0.04, 0.04, 0.04}, 0.0005);
  const double d = 2.0 * M_PI - 6.2;
  EXPECT_NEAR(RecoveryPolicy::disagreement(x, P, a), d * d / 0.0009, 1e-6);
  // Either way round.
  AlignmentResult b;
  b.imu = x;
  b.cov = a.cov;
  EXPECT_NEAR(RecoveryPolicy::disagreement(pose({0, 0, 1}, -3.1), P, b), d * d / 0.0009, 1e-6);
}

TEST(RecoveryPolicy, ContradictsBeyondTheBoundOnly) {
  RecoveryPolicy r(recovery(), kWindow_s);
  EXPECT_DOUBLE_EQ(r.bound(), 23.5);
  EXPECT_FALSE(r.contradicts(23.5));
  EXPECT_TRUE(r.contradicts(23.5001));
  EXPECT_FALSE(r.contradicts(4.0));
}
