#include "sim/lawnmower_trajectory.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "sim/random_stream.h"
#include "sim/trajectory_jets.h"

namespace meshnav::sim {

namespace {
constexpr double kShiftShare = 0.4;   ///< T_s / T_l
constexpr double kReturnShare = 1.5;  ///< T_ret / T_l
}  // namespace

LawnmowerTrajectory::LawnmowerTrajectory(const Hall& hall, double duration_s, uint64_t seed)
    : PadFlightTrajectory(PadFlightTiming::forDuration(duration_s)) {
  RandomStream rng(RandomStream::deriveSeed(seed, "trajectory:lawnmower"));
  axes_ = HallAxes::of(hall);
  half_length_m_ = axes_.reachU(0.5) * rng.uniform(0.85, 1.0);
  half_width_m_ = axes_.reachW(0.5) * rng.uniform(0.85, 1.0);
  lanes_ = std::clamp(static_cast<int>(std::floor(2.0 * half_width_m_ / rng.uniform(0.8, 1.4))) + 1, 2, 6);
  center_m_ = centralPad(hall);
  const double pattern_s = timing().pattern_end_s - timing().pattern_start_s;
  leg_s_ = pattern_s / (lanes_ + kShiftShare * (lanes_ - 1) + kReturnShare);
  shift_s_ = kShiftShare * leg_s_;
  return_s_ = kReturnShare * leg_s_;
  cruise_height_m_ = cruiseHeight(hall, rng.uniform(0.3, 0.5));
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
  const auto [x, y] = axes_.point(center_m_, u, w);
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
