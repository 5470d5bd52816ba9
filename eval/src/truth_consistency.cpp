#include "eval/truth_consistency.h"

#include "common/pose_interpolation.h"

#include <algorithm>
#include <cmath>

namespace meshnav::eval {

namespace {

/// Rotation angle of q in [0, π].
double angleOf(const Eigen::Quaterniond& q) {
  return 2.0 * std::acos(std::min(1.0, std::abs(q.normalized().w())));
}

}  // namespace

std::vector<TruthFault> truthGyroFaults(const std::vector<PoseSample>& truth, const std::vector<ImuSample>& imu,
                                        const TruthCheckOptions& options) {
  std::vector<TruthFault> faults;
  if (truth.size() < 2 || imu.size() < 2) return faults;
  const Duration max_gap = Duration::fromSec(2.0 * options.max_truth_dt_s);
  size_t i = 0;
  while (i + 1 < imu.size()) {
    // One window: the gyro integrated from sample i to the last sample within window_s of it.
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    size_t j = i;
    while (j + 1 < imu.size() && (imu[j + 1].t - imu[i].t).sec() <= options.window_s) {
      const double dt = (imu[j + 1].t - imu[j].t).sec();
      const Eigen::Vector3d rot = imu[j].gyro_rad_s * dt;
      const double a = rot.norm();
      if (a > 0.0) q = q * Eigen::Quaterniond(Eigen::AngleAxisd(a, rot / a));
      ++j;
    }
    if (j == i) {  // a gap longer than the window: move on
      ++i;
      continue;
    }
    const auto a = interpolatePose(truth, imu[i].t, max_gap), b = interpolatePose(truth, imu[j].t, max_gap);
    if (a && b) {
      const double th_truth = angleOf(a->q_ItoG.conjugate() * b->q_ItoG), th_gyro = angleOf(q);
      if (std::isfinite(th_truth) && std::abs(th_truth - th_gyro) > options.tolerance_rad) {
        // Overlapping windows that disagree are one fault (its angles: the largest disagreement).
        if (!faults.empty() && imu[i].t <= faults.back().t1) {
          TruthFault& f = faults.back();
          f.t1 = std::max(f.t1, imu[j].t);
          if (std::abs(th_truth - th_gyro) > std::abs(f.truth_angle_rad - f.gyro_angle_rad)) {
            f.truth_angle_rad = th_truth;
            f.gyro_angle_rad = th_gyro;
          }
        } else {
          faults.push_back({imu[i].t, imu[j].t, th_truth, th_gyro});
        }
      }
    }
    // Windows start every step_fraction of T, so a fault is not missed by the windows' phase.
    const size_t start = i;
    while (i + 1 < imu.size() && (imu[i].t - imu[start].t).sec() < options.window_s * options.step_fraction) ++i;
    if (i == start) ++i;
  }
  return faults;
}

size_t dropTruthInFaults(std::vector<PoseSample>& truth, const std::vector<TruthFault>& faults) {
  const size_t before = truth.size();
  truth.erase(std::remove_if(truth.begin(), truth.end(),
                             [&](const PoseSample& s) {
                               return std::any_of(faults.begin(), faults.end(), [&](const TruthFault& f) {
                                 return s.t >= f.t0 && s.t <= f.t1;
                               });
                             }),
              truth.end());
  return before - truth.size();
}

}  // namespace meshnav::eval
