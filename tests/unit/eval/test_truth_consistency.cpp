/// truthGyroFaults / dropTruthInFaults (eval/truth_consistency.h): the ground truth is checked
/// against the recording's gyro by the rotation angle over short windows, which no frame changes.
#include <gtest/gtest.h>

#include <cmath>

#include "eval/truth_consistency.h"

using namespace meshnav;
using namespace meshnav::eval;

namespace {

/// A body turning about a tilted axis with a rate that varies (0.3–1.1 rad/s), sampled at 200 Hz
/// for the IMU (ω in the body frame) and 100 Hz for the truth, over `duration_s`.
struct Recording {
  std::vector<ImuSample> imu;
  std::vector<PoseSample> truth;
};

Eigen::Vector3d omega(double t) {
  return Eigen::Vector3d(0.3 * std::sin(0.7 * t), 0.2, 0.7 + 0.4 * std::cos(1.3 * t));
}

Recording turning(double duration_s, const Eigen::Quaterniond& q_truth_body = Eigen::Quaterniond::Identity()) {
  Recording r;
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();  // body to world
  const double dt = 0.005;
  for (int k = 0; k * dt <= duration_s; ++k) {
    const double t = k * dt;
    r.imu.push_back({Timestamp::fromSec(t), Eigen::Vector3d(0, 0, 9.81), omega(t)});
    // The truth: a marker body rigidly attached to the IMU, q_truth = q · q_truth_body.
    if (k % 2 == 0) r.truth.push_back({Timestamp::fromSec(t), Eigen::Vector3d(t, 0, 1), q * q_truth_body});
    const Eigen::Vector3d a = omega(t) * dt;
    q = (q * Eigen::Quaterniond(Eigen::AngleAxisd(a.norm(), a.normalized()))).normalized();
  }
  return r;
}

}  // namespace

TEST(TruthConsistency, ACorrectTruthInAnyBodyFrameHasNoFault) {
  const Recording same = turning(20.0);
  EXPECT_TRUE(truthGyroFaults(same.truth, same.imu).empty());
  // The truth of a marker frame rotated 70° from the IMU: the angles still agree.
  const Recording marker = turning(20.0, Eigen::Quaterniond(Eigen::AngleAxisd(1.2, Eigen::Vector3d(1, 2, 3).normalized())));
  EXPECT_TRUE(truthGyroFaults(marker.truth, marker.imu).empty());
  // A gyro bias of 0.01 rad/s and a 30 ms clock offset of the truth stay within the tolerance.
  Recording off = turning(20.0);
  for (auto& s : off.imu) s.gyro_rad_s += Eigen::Vector3d(0.01, -0.01, 0.01);
  for (auto& s : off.truth) s.t = s.t + Duration::fromSec(0.03);
  EXPECT_TRUE(truthGyroFaults(off.truth, off.imu).empty());
}

TEST(TruthConsistency, AMotionCaptureFaultIsFoundAndItsPosesDropped) {
  // From 8.0 to 8.6 s the truth swings 40° about x and back (a marker swap), the gyro does not.
  Recording r = turning(20.0);
  for (auto& s : r.truth) {
    const double t = s.t.sec();
    if (t > 8.0 && t < 8.6)
      s.q_ItoG = s.q_ItoG * Eigen::Quaterniond(Eigen::AngleAxisd(0.7 * std::sin(M_PI * (t - 8.0) / 0.6), Eigen::Vector3d::UnitX()));
  }
  const auto faults = truthGyroFaults(r.truth, r.imu);
  ASSERT_EQ(faults.size(), 1u) << "overlapping windows are one fault";
  EXPECT_LE(faults[0].t0.sec(), 8.1);
  EXPECT_GE(faults[0].t1.sec(), 8.5);
  EXPECT_GT(faults[0].t0.sec(), 7.7);
  EXPECT_LT(faults[0].t1.sec(), 8.9);
  EXPECT_GT(std::abs(faults[0].truth_angle_rad - faults[0].gyro_angle_rad), 0.125);
  const size_t before = r.truth.size();
  const size_t dropped = dropTruthInFaults(r.truth, faults);
  EXPECT_EQ(before - r.truth.size(), dropped);
  EXPECT_GT(dropped, 40u);  // 0.4 s at least, at 100 Hz
  for (const auto& s : r.truth) EXPECT_FALSE(s.t.sec() > 8.1 && s.t.sec() < 8.5) << s.t.sec();
}

TEST(TruthConsistency, WithoutOverlapOrDataNothingIsClaimed) {
  const Recording r = turning(5.0);
  EXPECT_TRUE(truthGyroFaults({}, r.imu).empty());
  EXPECT_TRUE(truthGyroFaults(r.truth, {}).empty());
  // Truth from another time span: no window has truth at both ends, so none is judged.
  std::vector<PoseSample> later = r.truth;
  for (auto& s : later) s.t = s.t + Duration::fromSec(100.0);
  EXPECT_TRUE(truthGyroFaults(later, r.imu).empty());
}
