/// @file recovery_policy.cpp
/// @brief RecoveryPolicy: when to align and when an aligned pose replaces the filter's
/// (recovery_policy.h).

#include "estimator/health/recovery_policy.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "estimator/core/so3.h"

namespace meshnav::estimator {

bool RecoveryPolicy::evaluationDue(Timestamp t) {
  if (last_evaluation_ && (t - *last_evaluation_).sec() < kEvaluationPeriod_s) return false;
  last_evaluation_ = t;
  return true;
}

void RecoveryPolicy::noteImuGap(Timestamp t, double gap_s) {
  const double check_s = options_.after_gap_check_min_s;
  if (check_s > 0.0 && gap_s >= check_s) check_after_gap_until_ = t + Duration::fromSec(after_gap_window_s_);
}

bool RecoveryPolicy::alignmentDue(Timestamp t, Health h, bool accepted_fit) {
  const bool compare = options_.degraded_disagreement_chi2 > 0.0;
  const bool wanted = h == Health::Lost || (h == Health::Degraded && compare && !accepted_fit) || (compare && afterGap(t));
  if (!wanted || !options_.enabled) return false;
  if (last_try_ && (t - *last_try_).sec() < options_.retry_s) return false;
  last_try_ = t;
  return true;
}

double RecoveryPolicy::disagreement(const ImuState& x, const ImuMatrix& P, const AlignmentResult& r) {
  Eigen::Vector4d d;
  d.head<3>() = r.imu.p_IinG - x.p_IinG;
  d(3) = so3::yawDifference(so3::yawOf(r.imu.q_ItoG), so3::yawOf(x.q_ItoG));
  Eigen::Matrix4d S = Eigen::Matrix4d::Zero();
  S.topLeftCorner<3, 3>() = P.block<3, 3>(ImuErr::kP, ImuErr::kP) + r.cov.block<3, 3>(ImuErr::kP, ImuErr::kP);
  S(3, 3) = so3::yawVariance(x.q_ItoG, P.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta)) +
            so3::yawVariance(r.imu.q_ItoG, r.cov.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta));
  return d.dot(S.ldlt().solve(d));
}

}  // namespace meshnav::estimator
