#include "estimator/zupt/stillness_detector.h"

#include <algorithm>
#include <cmath>

namespace meshnav::estimator {

StillnessDetector::StillnessDetector(const StillnessOptions& options, double acc_noise_density,
                                     double gyro_noise_density, double gravity_m_s2)
    : options_(options), acc_nd_(acc_noise_density), gyro_nd_(gyro_noise_density), gravity_(gravity_m_s2) {}

bool StillnessDetector::add(const ImuSample& s) {
  if (!window_.empty() && s.t <= window_.back().t) return still_;
  window_.push_back(s);
  while ((s.t - window_.front().t).sec() > options_.window_s) window_.pop_front();
  const double span = (window_.back().t - window_.front().t).sec();
  if (window_.size() < 10 || span < 0.8 * options_.window_s) return still_ = false;
  const double n = static_cast<double>(window_.size());
  const double rate_hz = (n - 1.0) / span;
  Eigen::Vector3d mf = Eigen::Vector3d::Zero(), mw = Eigen::Vector3d::Zero();
  for (const ImuSample& x : window_) mf += x.acc_m_s2, mw += x.gyro_rad_s;
  mf /= n;
  mw /= n;
  Eigen::Vector3d vf = Eigen::Vector3d::Zero(), vw = Eigen::Vector3d::Zero();
  for (const ImuSample& x : window_) {
    vf += (x.acc_m_s2 - mf).cwiseAbs2();
    vw += (x.gyro_rad_s - mw).cwiseAbs2();
  }
  const double sf = std::sqrt(vf.maxCoeff() / (n - 1.0)), sw = std::sqrt(vw.maxCoeff() / (n - 1.0));
  const double max_f = std::max(options_.noise_factor * acc_nd_ * std::sqrt(rate_hz), options_.acc_floor_m_s2);
  const double max_w = std::max(options_.noise_factor * gyro_nd_ * std::sqrt(rate_hz), options_.gyro_floor_rad_s);
  still_ = sf <= max_f && sw <= max_w && std::abs(mf.norm() - gravity_) <= options_.gravity_tolerance_m_s2 &&
           mw.norm() <= options_.max_mean_rate_rad_s;
  return still_;
}

}  // namespace meshnav::estimator
