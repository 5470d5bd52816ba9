#include "sim/spiral_trajectory.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "sim/random_stream.h"
#include "sim/trajectory_jets.h"

namespace meshnav::sim {

namespace {
using JetP = PositionJet;
}  // namespace

TrajectoryOptions TrajectoryOptions::randomized(uint64_t seed, double duration_scale) {
  RandomStream rng(RandomStream::deriveSeed(seed, "trajectory"));
  TrajectoryOptions o;
  // Timing: nominal ~140 s with a few seconds of jitter per phase.
  o.takeoff_start_s = 5.0 + rng.uniform(-0.5, 0.5);
  o.takeoff_duration_s = 6.0 + rng.uniform(-0.5, 0.5);
  o.spiral_start_s = o.takeoff_start_s + o.takeoff_duration_s + rng.uniform(0.5, 1.5);
  o.spiral_ramp_s = 6.0 + rng.uniform(-1.0, 1.0);
  o.spiral_end_s = o.spiral_start_s + 107.0 + rng.uniform(-3.0, 3.0);
  o.landing_start_s = o.spiral_end_s + rng.uniform(0.5, 1.5);
  o.landing_duration_s = 12.0 + rng.uniform(-1.0, 1.0);
  o.duration_s = o.landing_start_s + o.landing_duration_s + 5.0 + rng.uniform(-0.5, 0.5);
  // Geometry.
  o.pad_height_m = 0.12;
  o.hover_height_m = 2.0 + rng.uniform(-0.1, 0.1);
  o.top_height_m = 7.6 + rng.uniform(0.0, 0.2);
  o.center_x_m = 0.3 + rng.uniform(-0.1, 0.1);
  o.center_y_m = rng.uniform(-0.1, 0.1);
  o.semi_axis_x_m = 1.5 + rng.uniform(-0.1, 0.1);
  o.semi_axis_y_m = 3.0 + rng.uniform(-0.15, 0.15);
  o.mid_shrink = rng.uniform(0.05, 0.25);
  o.theta0_rad = rng.uniform(-kPi, kPi);
  o.radial_wobble = rng.uniform(0.03, 0.06);
  o.radial_wobble_period_s = rng.uniform(5.0, 8.0);
  o.radial_wobble_phase_rad = rng.uniform(-kPi, kPi);
  o.direction = rng.bernoulli(0.5) ? 1.0 : -1.0;
  o.z_wobble_amplitude_m = rng.uniform(0.1, 0.2);
  o.z_wobble_period_s = rng.uniform(8.0, 14.0);
  o.z_wobble_phase_rad = rng.uniform(-kPi, kPi);
  o.yaw0_rad = rng.uniform(-kPi, kPi);
  o.yaw_follow = rng.uniform(0.0, 1.0);
  o.yaw_wobble_amplitude_rad = rng.uniform(0.15, 0.45);
  o.yaw_wobble_period_s = rng.uniform(15.0, 30.0);
  o.yaw_wobble_phase_rad = rng.uniform(-kPi, kPi);
  // Scale every time constant (not the geometry).
  for (double* t : {&o.takeoff_start_s, &o.takeoff_duration_s, &o.spiral_start_s, &o.spiral_ramp_s, &o.spiral_end_s,
                    &o.landing_start_s, &o.landing_duration_s, &o.duration_s, &o.z_wobble_period_s, &o.radial_wobble_period_s,
                    &o.yaw_wobble_period_s})
    *t *= duration_scale;
  o.validate();
  return o;
}

TrajectoryOptions TrajectoryOptions::fittedTo(const Hall& hall) const {
  const Hall paper = Hall::paper();
  const Eigen::Vector3d scale = hall.size().cwiseQuotient(paper.size());
  const double height_scale = (hall.size().z() - 0.5) / (paper.size().z() - 0.5);
  TrajectoryOptions o = *this;
  o.center_x_m = hall.min_m.x() + (center_x_m - paper.min_m.x()) * scale.x();
  o.center_y_m = hall.min_m.y() + (center_y_m - paper.min_m.y()) * scale.y();
  o.semi_axis_x_m = semi_axis_x_m * scale.x();
  o.semi_axis_y_m = semi_axis_y_m * scale.y();
  o.hover_height_m = std::max(pad_height_m + 0.5, hover_height_m * height_scale);
  o.top_height_m = std::max(o.hover_height_m + 0.3, top_height_m * height_scale);
  o.z_wobble_amplitude_m = z_wobble_amplitude_m * std::min(1.0, height_scale);
  o.validate();
  return o;
}

void TrajectoryOptions::validate() const {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("TrajectoryOptions: ") + what);
  };
  require(takeoff_start_s >= 0.0, "takeoff_start_s must be >= 0");
  require(takeoff_duration_s > 0.0, "takeoff_duration_s must be > 0");
  require(spiral_ramp_s > 0.0, "spiral_ramp_s must be > 0");
  require(spiral_end_s - spiral_start_s >= 2.0 * spiral_ramp_s, "spiral_end_s - spiral_start_s must be >= 2 spiral_ramp_s");
  require(landing_start_s >= spiral_end_s, "landing_start_s must be >= spiral_end_s");
  require(landing_duration_s > 0.0, "landing_duration_s must be > 0");
  require(duration_s >= landing_start_s + landing_duration_s, "duration_s must cover the landing");
  require(turns > 0.0, "turns must be > 0");
  require(semi_axis_x_m > 0.0 && semi_axis_y_m > 0.0, "semi axes must be > 0");
  require(mid_shrink >= 0.0 && mid_shrink < 1.0, "mid_shrink must be in [0, 1)");
  require(direction == 1.0 || direction == -1.0, "direction must be +1 or -1");
  require(z_wobble_period_s > 0.0 && yaw_wobble_period_s > 0.0 && radial_wobble_period_s > 0.0,
          "wobble periods must be > 0");
  require(radial_wobble >= 0.0 && radial_wobble < 0.5, "radial_wobble must be in [0, 0.5)");
}

std::string TrajectoryOptions::toString() const {
  std::ostringstream s;
  s << "trajectory: takeoff " << takeoff_start_s << " s (+" << takeoff_duration_s << " s) to " << hover_height_m
    << " m; " << turns << " spirals " << spiral_start_s << "-" << spiral_end_s << " s (ramp " << spiral_ramp_s
    << " s) to " << top_height_m << " m; ellipse centre [" << center_x_m << ", " << center_y_m << "] m, semi-axes "
    << semi_axis_x_m << " x " << semi_axis_y_m << " m, shrink " << mid_shrink << ", radial wobble " << radial_wobble
    << " / " << radial_wobble_period_s << " s, theta0 " << theta0_rad
    << " rad, dir " << direction << "; z wobble " << z_wobble_amplitude_m << " m / " << z_wobble_period_s
    << " s; yaw0 " << yaw0_rad << " rad, follow " << yaw_follow << ", wobble " << yaw_wobble_amplitude_rad
    << " rad / " << yaw_wobble_period_s << " s; landing " << landing_start_s << " s (+" << landing_duration_s
    << " s); end " << duration_s << " s";
  return s.str();
}

SpiralTrajectory::SpiralTrajectory(const TrajectoryOptions& options) : options_(options) { options_.validate(); }

bool SpiralTrajectory::isLanded(double t_s) const { return t_s <= takeoffTime() || t_s >= touchdownTime(); }

Eigen::Vector3d SpiralTrajectory::padPosition() const {
  const auto& o = options_;
  return {o.center_x_m + o.semi_axis_x_m * std::cos(o.theta0_rad),
          o.center_y_m + o.semi_axis_y_m * std::sin(o.theta0_rad), o.pad_height_m};
}

TrajectoryState SpiralTrajectory::evaluate(double t_s) const {
  const auto& o = options_;
  const JetP t = JetP::variable(t_s);

  // Spiral phase, progress and speed envelope.
  const double t_a = o.spiral_start_s;
  const double t_b = o.spiral_end_s - o.spiral_ramp_s;
  const double T_r = o.spiral_ramp_s;
  const double total_angle = 2.0 * kPi * o.turns;
  const double omega_max = total_angle / (t_b - t_a);
  const JetP ramp = smoothStepIntegral((t - t_a) / T_r) - smoothStepIntegral((t - t_b) / T_r);
  const JetP progress = ramp * (omega_max * T_r / total_angle);
  const JetP theta = o.theta0_rad + (o.direction * total_angle) * progress;
  const JetP envelope = smoothStep((t - t_a) / T_r) - smoothStep((t - t_b) / T_r);

  // Horizontal ellipse with a mid-flight shrink and a radial oscillation:
  // m = 1 − δ sin²(π progress) + A_r e(t) sin(2πt/P_r + φ_r).
  const JetP s_pi = sin(kPi * progress);
  const JetP m = 1.0 - o.mid_shrink * (s_pi * s_pi) +
                 o.radial_wobble *
                     (envelope * sin(t * (2.0 * kPi / o.radial_wobble_period_s) + o.radial_wobble_phase_rad));
  JetP sin_theta, cos_theta;
  sincos(theta, sin_theta, cos_theta);
  const JetP x = o.center_x_m + o.semi_axis_x_m * (m * cos_theta);
  const JetP y = o.center_y_m + o.semi_axis_y_m * (m * sin_theta);

  // Height: take-off, climb with the spiral progress, wobble, landing.
  const JetP z = o.pad_height_m + (o.hover_height_m - o.pad_height_m) * smoothStep((t - o.takeoff_start_s) / o.takeoff_duration_s) +
                 (o.top_height_m - o.hover_height_m) * progress +
                 o.z_wobble_amplitude_m * (envelope * sin(t * (2.0 * kPi / o.z_wobble_period_s) + o.z_wobble_phase_rad)) -
                 (o.top_height_m - o.pad_height_m) * smoothStep((t - o.landing_start_s) / o.landing_duration_s);

  // Heading.
  const JetP psi = o.yaw0_rad + o.yaw_follow * (theta - o.theta0_rad) +
                   o.yaw_wobble_amplitude_rad *
                       (envelope * sin(t * (2.0 * kPi / o.yaw_wobble_period_s) + o.yaw_wobble_phase_rad));

  return quadrotorState(t_s, {x, y, z}, psi);
}

}  // namespace meshnav::sim
