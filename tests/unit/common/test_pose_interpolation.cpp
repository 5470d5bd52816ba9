#include <gtest/gtest.h>

#include "common/pose_interpolation.h"

using namespace meshnav;

TEST(PoseInterpolation, LinearPositionAndSlerp) {
  std::vector<PoseSample> v{{Timestamp::fromSec(0), {0, 0, 0}, Eigen::Quaterniond::Identity()},
                            {Timestamp::fromSec(1), {2, 0, 0}, Eigen::Quaterniond(Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitZ()))}};
  auto p = interpolatePose(v, Timestamp::fromSec(0.25), Duration::fromSec(2));
  ASSERT_TRUE(p);
  EXPECT_TRUE(p->p_IinG.isApprox(Eigen::Vector3d(0.5, 0, 0)));
  EXPECT_NEAR(Eigen::AngleAxisd(p->q_ItoG).angle(), 0.25, 1e-12);
  EXPECT_TRUE(interpolatePose(v, Timestamp::fromSec(1), Duration::fromSec(2)));
  EXPECT_FALSE(interpolatePose(v, Timestamp::fromSec(1.01), Duration::fromSec(2)));
  EXPECT_TRUE(interpolatePose(v, Timestamp::fromSec(1.01), Duration::fromSec(2), Duration::fromSec(0.1)));
}

TEST(PoseInterpolation, GapTooLargeGivesNothing) {
  std::vector<PoseSample> v{{Timestamp::fromSec(0), {0, 0, 0}, Eigen::Quaterniond::Identity()},
                            {Timestamp::fromSec(2), {2, 0, 0}, Eigen::Quaterniond::Identity()}};
  EXPECT_FALSE(interpolatePose(v, Timestamp::fromSec(1), Duration::fromSec(0.5)));
  EXPECT_TRUE(interpolatePose(v, Timestamp::fromSec(1), Duration::fromSec(3)));
  EXPECT_FALSE(interpolatePose({}, Timestamp::fromSec(1)));
}
