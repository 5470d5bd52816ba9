#include "sim/walk_trajectory.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "sim/random_stream.h"
#include "sim/trajectory_jets.h"

namespace meshnav::sim {

namespace {
constexpr double kDegToRad = kPi / 180.0;

/// Walking window: standing ~3 s at both ends (less for short sequences), 2 s speed ramps.
SmoothProgress walkingWindow(double duration_s) {
  if (!(duration_s >= 20.0)) throw std::invalid_argument("WalkTrajectory: duration must be >= 20 s");
  const double stand_s = std::min(3.0, 0.05 * duration_s);
  return SmoothProgress(stand_s, 2.0, duration_s - stand_s);
}
}  // namespace

WalkTrajectory::WalkTrajectory(const Hall& hall, double duration_s, uint64_t seed)
    : duration_s_(duration_s), walking_(walkingWindow(duration_s)) {
  RandomStream rng(RandomStream::deriveSeed(seed, "trajectory:walk"));
  const Eigen::Vector3d size = hall.size();
  center_m_ = hall.center().head<2>();
  semi_a_m_ = std::max(0.5, 0.5 * size.x() - 0.8) * rng.uniform(0.8, 1.0);
  semi_b_m_ = std::max(0.5, 0.5 * size.y() - 0.8) * rng.uniform(0.8, 1.0);
  theta0_rad_ = rng.uniform(-kPi, kPi);
  direction_ = rng.bernoulli(0.5) ? 1.0 : -1.0;
  speed_m_s_ = rng.uniform(0.9, 1.3);
  // Ramanujan's ellipse perimeter; Θ so that the mean speed at full envelope is v.
  const double h = std::pow((semi_a_m_ - semi_b_m_) / (semi_a_m_ + semi_b_m_), 2);
  const double perimeter_m = kPi * (semi_a_m_ + semi_b_m_) * (1.0 + 3.0 * h / (10.0 + std::sqrt(4.0 - 3.0 * h)));
  const double full_speed_s = walking_.end() - walking_.start() - 2.0;  // ∫e dt = t_b − t_a
  total_angle_rad_ = 2.0 * kPi * speed_m_s_ * full_speed_s / perimeter_m;
  step_hz_ = rng.uniform(1.7, 1.9);
  height_m_ = rng.uniform(1.1, 1.3);
  height_amp_m_ = rng.uniform(0.05, 0.12);
  height_period_s_ = rng.uniform(20.0, 40.0);
  height_phase_rad_ = rng.uniform(-kPi, kPi);
  bob_m_ = rng.uniform(0.015, 0.03);
  sway_m_ = rng.uniform(0.01, 0.025);
  yaw_sway_rad_ = rng.uniform(1.0, 3.0) * kDegToRad;
  pitch0_rad_ = rng.uniform(-5.0, 5.0) * kDegToRad;
  pitch_sway_rad_ = rng.uniform(0.5, 2.0) * kDegToRad;
  roll_sway_rad_ = rng.uniform(1.0, 3.0) * kDegToRad;
  for (double& ph : phase_rad_) ph = rng.uniform(-kPi, kPi);
}

TrajectoryState WalkTrajectory::evaluate(double t_s) const {
  const PositionJet t = PositionJet::variable(t_s);
  const PositionJet e = walking_.envelope(t);
  const PositionJet theta = theta0_rad_ + (direction_ * total_angle_rad_) * walking_.progress(t);
  PositionJet sin_theta, cos_theta;
  sincos(theta, sin_theta, cos_theta);
  const PositionJet walk_yaw = atan2((direction_ * semi_b_m_) * cos_theta, (-direction_ * semi_a_m_) * sin_theta);
  PositionJet sin_yaw, cos_yaw;
  sincos(walk_yaw, sin_yaw, cos_yaw);
  const PositionJet step = t * (2.0 * kPi * step_hz_);  // 2π f t
  const PositionJet half_step = t * (kPi * step_hz_);   // π f t
  const PositionJet sway = sway_m_ * (e * sin(half_step + phase_rad_[0]));
  const PositionJet x = center_m_.x() + semi_a_m_ * cos_theta - sway * sin_yaw;
  const PositionJet y = center_m_.y() + semi_b_m_ * sin_theta + sway * cos_yaw;
  const PositionJet z = height_m_ + height_amp_m_ * sin(t * (2.0 * kPi / height_period_s_) + height_phase_rad_) +
                        bob_m_ * (e * sin(step + phase_rad_[1]));
  const PositionJet yaw = walk_yaw + yaw_sway_rad_ * (e * sin(half_step + phase_rad_[2]));
  const PositionJet pitch = pitch0_rad_ + pitch_sway_rad_ * (e * sin(step + phase_rad_[3]));
  const PositionJet roll = roll_sway_rad_ * (e * sin(half_step + phase_rad_[4]));
  return yawPitchRollState(t_s, {x, y, z}, yaw, pitch, roll);
}

std::string WalkTrajectory::toString() const {
  std::ostringstream s;
  s << "walk: hand-held, ellipse " << semi_a_m_ << " x " << semi_b_m_ << " m around [" << center_m_.transpose()
    << "] m, " << total_angle_rad_ / (2.0 * kPi) << " laps (dir " << direction_ << ") at " << speed_m_s_
    << " m/s, steps " << step_hz_ << " Hz (bob " << bob_m_ << " m, sway " << sway_m_ << " m), height " << height_m_
    << " +- " << height_amp_m_ << " m, pitch " << pitch0_rad_ << " rad; walking " << walking_.start() << "-"
    << walking_.end() << " s of " << duration_s_ << " s; no take-off, no landed phase, no barometer";
  return s.str();
}

}  // namespace meshnav::sim
