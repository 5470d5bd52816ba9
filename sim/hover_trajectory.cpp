#include "sim/hover_trajectory.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "sim/random_stream.h"
#include "sim/trajectory_jets.h"

namespace meshnav::sim {

HoverTrajectory::HoverTrajectory(const Hall& hall, double duration_s, uint64_t seed) : duration_s_(duration_s) {
  if (!(duration_s > 0.0)) throw std::invalid_argument("HoverTrajectory: duration must be > 0 s");
  RandomStream rng(RandomStream::deriveSeed(seed, "trajectory:hover"));
  const Eigen::Vector3d size = hall.size();
  center_m_ = hall.center();
  center_m_.x() += rng.uniform(-0.15, 0.15) * size.x();
  center_m_.y() += rng.uniform(-0.15, 0.15) * size.y();
  center_m_.z() = std::clamp(rng.uniform(0.25, 0.45) * size.z(), 1.2, size.z() - 1.0);
  for (int i = 0; i < 3; ++i) {
    const double scale = i < 2 ? 1.0 : 0.4;
    amp1_m_[i] = scale * rng.uniform(0.1, 0.25);
    amp2_m_[i] = scale * rng.uniform(0.03, 0.1);
    period1_s_[i] = rng.uniform(15.0, 40.0);
    period2_s_[i] = rng.uniform(4.0, 9.0);
    phase1_rad_[i] = rng.uniform(-kPi, kPi);
    phase2_rad_[i] = rng.uniform(-kPi, kPi);
  }
  yaw_ = HeadingWobble::draw(rng, 0.1, 0.5, 15.0, 40.0);
}

TrajectoryState HoverTrajectory::evaluate(double t_s) const {
  const PositionJet t = PositionJet::variable(t_s);
  PositionJet3 p;
  for (int i = 0; i < 3; ++i)
    p[i] = center_m_[i] + amp1_m_[i] * sin(t * (2.0 * kPi / period1_s_[i]) + phase1_rad_[i]) +
           amp2_m_[i] * sin(t * (2.0 * kPi / period2_s_[i]) + phase2_rad_[i]);
  return quadrotorState(t_s, p, yaw_.at(t));
}

std::string HoverTrajectory::toString() const {
  std::ostringstream s;
  s << "hover: in the air from the start at [" << center_m_.transpose() << "] m, drift amplitudes ["
    << (amp1_m_ + amp2_m_).transpose() << "] m, yaw0 " << yaw_.yaw0_rad << " rad +- " << yaw_.amplitude_rad
    << " rad; " << duration_s_ << " s, no landed phase";
  return s.str();
}

}  // namespace meshnav::sim
