#include "sim/helix_trajectory.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "sim/random_stream.h"
#include "sim/trajectory_jets.h"

namespace meshnav::sim {

HelixTrajectory::HelixTrajectory(const Hall& hall, double duration_s, uint64_t seed)
    : PadFlightTrajectory(PadFlightTiming::forDuration(duration_s)) {
  RandomStream rng(RandomStream::deriveSeed(seed, "trajectory:helix"));
  const Eigen::Vector3d size = hall.size();
  center_m_ = centralPad(hall);
  radius_m_ = HallAxes::of(hall).reachW(0.5) * rng.uniform(0.75, 1.0);
  const double pattern_s = timing().pattern_end_s - timing().pattern_start_s;
  turns_ = std::max(1.0, std::round(pattern_s / rng.uniform(20.0, 30.0)));
  direction_ = rng.bernoulli(0.5) ? 1.0 : -1.0;
  theta0_rad_ = rng.uniform(-kPi, kPi);
  low_height_m_ = std::clamp(rng.uniform(0.15, 0.3) * size.z(), 0.8, 2.0);
  top_height_m_ = std::max(low_height_m_ + 0.5, size.z() - rng.uniform(0.6, 1.2));
}

TrajectoryState HelixTrajectory::evaluate(double t_s) const {
  const PositionJet t = PositionJet::variable(t_s);
  const PositionJet progress = pattern().progress(t);
  const PositionJet theta = theta0_rad_ + (direction_ * 2.0 * kPi * turns_) * progress;
  PositionJet sin_theta, cos_theta;
  sincos(theta, sin_theta, cos_theta);
  const PositionJet x = center_m_.x() + radius_m_ * cos_theta;
  const PositionJet y = center_m_.y() + radius_m_ * sin_theta;
  const PositionJet z = center_m_.z() + (low_height_m_ - center_m_.z()) * airborne(t) +
                        (0.5 * (top_height_m_ - low_height_m_)) * (1.0 - cos((2.0 * kPi) * progress));
  const PositionJet psi = theta + direction_ * 0.5 * kPi;
  return quadrotorState(t_s, {x, y, z}, psi);
}

std::string HelixTrajectory::toString() const {
  std::ostringstream s;
  s << "helix: " << turns_ << " turns (dir " << direction_ << ") of radius " << radius_m_ << " m around ["
    << center_m_.x() << ", " << center_m_.y() << "] m from " << low_height_m_ << " m up to " << top_height_m_
    << " m and back, theta0 " << theta0_rad_ << " rad; " << timing().toString();
  return s.str();
}

}  // namespace meshnav::sim
