#include "sim/figure8_trajectory.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "sim/random_stream.h"
#include "sim/trajectory_jets.h"

namespace meshnav::sim {

Figure8Trajectory::Figure8Trajectory(const Hall& hall, double duration_s, uint64_t seed)
    : PadFlightTrajectory(PadFlightTiming::forDuration(duration_s)) {
  RandomStream rng(RandomStream::deriveSeed(seed, "trajectory:figure8"));
  const Eigen::Vector3d size = hall.size();
  axes_ = HallAxes::of(hall);
  amplitude_u_m_ = axes_.reachU(0.3) * rng.uniform(0.8, 1.0);
  amplitude_w_m_ = 2.0 * axes_.reachW(0.3) * rng.uniform(0.8, 1.0);  // |B/2 sin 2θ| ≤ B/2
  center_m_ = centralPad(hall);
  const double pattern_s = timing().pattern_end_s - timing().pattern_start_s;
  loops_ = std::max(1.0, std::round(pattern_s / rng.uniform(20.0, 30.0)));
  cruise_height_m_ = cruiseHeight(hall, rng.uniform(0.25, 0.5));
  z_amplitude_m_ = std::min(0.3, 0.1 * size.z()) * rng.uniform(0.5, 1.0);
  z_period_s_ = rng.uniform(8.0, 14.0);
  z_phase_rad_ = rng.uniform(-kPi, kPi);
  yaw_ = HeadingWobble::draw(rng, 0.2, 0.6, 15.0, 30.0);
}

TrajectoryState Figure8Trajectory::evaluate(double t_s) const {
  const PositionJet t = PositionJet::variable(t_s);
  const PositionJet e = pattern().envelope(t);
  const PositionJet theta = (2.0 * kPi * loops_) * pattern().progress(t);
  const PositionJet along = amplitude_u_m_ * sin(theta);
  const PositionJet across = (0.5 * amplitude_w_m_) * sin(2.0 * theta);
  const auto [x, y] = axes_.point(center_m_, along, across);
  const PositionJet z = center_m_.z() + (cruise_height_m_ - center_m_.z()) * airborne(t) +
                        z_amplitude_m_ * (e * sin(t * (2.0 * kPi / z_period_s_) + z_phase_rad_));
  return quadrotorState(t_s, {x, y, z}, yaw_.at(t, e));
}

std::string Figure8Trajectory::toString() const {
  std::ostringstream s;
  s << "figure8: " << loops_ << " loops, centre [" << center_m_.x() << ", " << center_m_.y() << "] m, amplitudes "
    << amplitude_u_m_ << " / " << 0.5 * amplitude_w_m_ << " m, cruise " << cruise_height_m_ << " m, z wobble "
    << z_amplitude_m_ << " m / " << z_period_s_ << " s, yaw0 " << yaw_.yaw0_rad << " rad +- " << yaw_.amplitude_rad
    << " rad; " << timing().toString();
  return s.str();
}

}  // namespace meshnav::sim
