#include "sim/lawnmower_trajectory.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "sim/random_stream.h"
#include "sim/trajectory_jets.h"

namespace meshnav::sim {

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kShiftShare = 0.4;   ///< T_s / T_l
constexpr double kReturnShare = 1.5;  ///< T_ret / T_l
}  // namespace

LawnmowerTrajectory::LawnmowerTrajectory(const Hall& hall, double duration_s, uint64_t seed)
    : PadFlightTrajectory(PadFlightTiming::forDuration(duration_s)) {
  RandomStream rng(RandomStream::deriveSeed(seed, "trajectory:lawnmower"));
  const Eigen::Vector3d size = hall.size();
  const bool x_long = size.x() >= size.y();
  u_axis_ = x_long ? Eigen::Vector2d::UnitX() : Eigen::Vector2d::UnitY();
  w_axis_ = x_long ? Eigen::Vector2d::UnitY() : Eigen::Vector2d::UnitX();
  half_length_m_ = std::max(0.5, 0.5 * std::max(size.x(), size.y()) - 0.7) * rng.uniform(0.85, 1.0);
  half_width_m_ = std::max(0.5, 0.5 * std::min(size.x(), size.y()) - 0.7) * rng.uniform(0.85, 1.0);
  lanes_ = std::clamp(static_cast<int>(std::floor(2.0 * half_width_m_ / rng.uniform(0.8, 1.4))) + 1, 2, 6);
  center_m_ = Eigen::Vector3d(hall.center().x(), hall.center().y(), kPadHeight_m);
  const double pattern_s = timing().pattern_end_s - timing().pattern_start_s;
  leg_s_ = pattern_s / (lanes_ + kShiftShare * (lanes_ - 1) + kReturnShare);
  shift_s_ = kShiftShare * leg_s_;
  return_s_ = kReturnShare * leg_s_;
  cruise_height_m_ = std::clamp(rng.uniform(0.3, 0.5) * size.z(), 1.0, size.z() - 1.0);
  yaw0_rad_ = rng.uniform(-kPi, kPi);
  yaw_amplitude_rad_ = rng.uniform(0.1, 0.4);
  yaw_period_s_ = rng.uniform(15.0, 30.0);
}

TrajectoryState LawnmowerTrajectory::evaluate(double t_s) const {
  const PositionJet t = PositionJet::variable(t_s);
  const double t0 = timing().pattern_start_s;
  const double spacing_m = 2.0 * half_width_m_ / (lanes_ - 1);
  PositionJet u = PositionJet::constant(-half_length_m_);
  PositionJet w = PositionJet::constant(-half_width_m_);
  double u_end = -half_length_m_;
  for (int i = 0; i < lanes_; ++i) {
    const double a_i = t0 + i * (leg_s_ + shift_s_);
    const double sign = (i % 2 == 0) ? 1.0 : -1.0;
    u = u + (sign * 2.0 * half_length_m_) * smoothStep((t - a_i) / leg_s_);
    u_end += sign * 2.0 * half_length_m_;
    if (i + 1 < lanes_) w = w + spacing_m * smoothStep((t - (a_i + leg_s_)) / shift_s_);
  }
  const double a_ret = t0 + (lanes_ - 1) * (leg_s_ + shift_s_) + leg_s_;
  const PositionJet back = smoothStep((t - a_ret) / return_s_);
  u = u - (u_end + half_length_m_) * back;
  w = w - (2.0 * half_width_m_) * back;
  const PositionJet x = center_m_.x() + u_axis_.x() * u + w_axis_.x() * w;
  const PositionJet y = center_m_.y() + u_axis_.y() * u + w_axis_.y() * w;
  const PositionJet z = center_m_.z() + (cruise_height_m_ - center_m_.z()) * airborne(t);
  const PositionJet e = pattern().envelope(t);
  const PositionJet psi = yaw0_rad_ + yaw_amplitude_rad_ * (e * sin(t * (2.0 * kPi / yaw_period_s_)));
  return quadrotorState(t_s, {x, y, z}, psi);
}

std::string LawnmowerTrajectory::toString() const {
  std::ostringstream s;
  s << "lawnmower: " << lanes_ << " lanes of " << 2.0 * half_length_m_ << " m over " << 2.0 * half_width_m_
    << " m around [" << center_m_.x() << ", " << center_m_.y() << "] m at " << cruise_height_m_ << " m; legs "
    << leg_s_ << " s, shifts " << shift_s_ << " s, return " << return_s_ << " s; yaw0 " << yaw0_rad_ << " rad +- "
    << yaw_amplitude_rad_ << " rad; " << timing().toString();
  return s.str();
}

}  // namespace meshnav::sim
