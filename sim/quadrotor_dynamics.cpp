#include "sim/quadrotor_dynamics.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <variant>

#include "common/options_list.h"
#include "sim/trajectory.h"

namespace meshnav::sim {

namespace {

using Ref = std::variant<double*, Eigen::Vector3d*>;

template <auto... path>
constexpr auto at = &memberAt<QuadrotorOptions, Ref, path...>;

/// Every option as (key, member, unit): the one list reading and printing share.
const OptionField<QuadrotorOptions, Ref> kFields[] = {
    {"integration_rate_hz", at<&QuadrotorOptions::integration_rate_hz>, "[Hz]"},
    {"thrust_time_constant_s", at<&QuadrotorOptions::thrust_time_constant_s>, "[s]"},
    {"rate_time_constant_s", at<&QuadrotorOptions::rate_time_constant_s>, "[s]"},
    {"drag_per_s", at<&QuadrotorOptions::drag_per_s>, "[1/s]"},
    {"max_thrust_m_s2", at<&QuadrotorOptions::max_thrust_m_s2>, "[m/s^2]"},
    {"max_rate_rad_s", at<&QuadrotorOptions::max_rate_rad_s>, "[rad/s]"},
    {"crash_speed_m_s", at<&QuadrotorOptions::crash_speed_m_s>, "[m/s]"},
    {"pad_height_m", at<&QuadrotorOptions::pad_height_m>, "[m]"},
    {"wind_mean_m_s", at<&QuadrotorOptions::wind_mean_m_s>, "[m/s]"},
    {"gust_sigma_m_s", at<&QuadrotorOptions::gust_sigma_m_s>, "[m/s]"},
    {"gust_time_constant_s", at<&QuadrotorOptions::gust_time_constant_s>, "[s]"},
    {"hall_min_m", at<&QuadrotorOptions::hall_min_m>, "[m]"},
    {"hall_max_m", at<&QuadrotorOptions::hall_max_m>, "[m]"},
};

template <typename Opts, typename F>
void visitOptions(Opts& o, F&& f) {
  forEachOption(o, kFields, f);
}

Eigen::Matrix3d skew(const Eigen::Vector3d& w) {
  Eigen::Matrix3d S;
  S << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return S;
}

/// Exp: so(3) → SO(3) (Rodrigues).
Eigen::Matrix3d expSO3(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  if (a < 1e-12) return Eigen::Matrix3d::Identity() + skew(phi);
  return Eigen::AngleAxisd(a, phi / a).toRotationMatrix();
}

/// R with roll and pitch removed: the rotation about z with the same heading.
Eigen::Matrix3d levelled(const Eigen::Matrix3d& R) {
  return Eigen::AngleAxisd(std::atan2(R(1, 0), R(0, 0)), Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace

QuadrotorOptions QuadrotorOptions::fromYaml(const YAML::Node& node, const std::string& where) {
  YamlOptions yaml(node, where, "vehicle");
  return readOptionsList<QuadrotorOptions>(yaml, [](auto& o, auto&& f) { visitOptions(o, f); });
}

void QuadrotorOptions::validate() const {
  auto require = [](bool ok, const char* key, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("key 'vehicle.") + key + "' must be " + what);
  };
  require(integration_rate_hz >= 50.0 && integration_rate_hz <= 1e5, "integration_rate_hz", "in [50, 1e5]");
  require(thrust_time_constant_s > 0.0, "thrust_time_constant_s", "> 0");
  require(rate_time_constant_s > 0.0, "rate_time_constant_s", "> 0");
  require(drag_per_s >= 0.0, "drag_per_s", ">= 0");
  require(max_thrust_m_s2 > Trajectory::kGravity_m_s2, "max_thrust_m_s2", "> g (9.81)");
  require(max_rate_rad_s > 0.0, "max_rate_rad_s", "> 0");
  require(crash_speed_m_s > 0.0, "crash_speed_m_s", "> 0");
  require(gust_sigma_m_s >= 0.0, "gust_sigma_m_s", ">= 0");
  require(gust_time_constant_s > 0.0, "gust_time_constant_s", "> 0");
  require((hall_max_m - hall_min_m).minCoeff() > 0.0, "hall_max_m", "above hall_min_m on every axis");
  require(pad_height_m >= hall_min_m.z() && pad_height_m < hall_max_m.z(), "pad_height_m", "inside the hall");
}

std::string QuadrotorOptions::toString() const {
  std::ostringstream s;
  visitOptions(*this, [&](const auto& key, const auto& field, const char* unit) {
    s << "  " << key << ": ";
    if constexpr (std::is_same_v<std::decay_t<decltype(field)>, Eigen::Vector3d>)
      s << "[" << field.x() << ", " << field.y() << ", " << field.z() << "]";
    else
      s << field;
    s << "  # " << unit << "\n";
  });
  return s.str();
}

QuadrotorDynamics::QuadrotorDynamics(const QuadrotorOptions& options, const Eigen::Vector3d& p_IinG, double yaw_rad,
                                     uint64_t seed)
    : options_(options),
      dt_(1.0 / options.integration_rate_hz),
      rng_wind_(RandomStream::deriveSeed(seed, "wind_gusts")) {
  options_.validate();
  p_ = p_IinG;
  p_.z() = options_.pad_height_m;
  R_ = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  if (options_.gust_sigma_m_s > 0.0) gust_G_ = rng_wind_.gaussian3(options_.gust_sigma_m_s);
  wind_G_ = options_.wind_mean_m_s + gust_G_;
}

void QuadrotorDynamics::setState(const Eigen::Vector3d& p_IinG, const Eigen::Vector3d& v_IinG,
                                 const Eigen::Matrix3d& R_ItoG, const Eigen::Vector3d& w_IinI, double thrust_m_s2) {
  p_ = p_IinG;
  v_ = v_IinG;
  R_ = R_ItoG;
  w_ = w_IinI;
  thrust_ = thrust_m_s2;
  landed_ = p_.z() <= options_.pad_height_m && v_.norm() == 0.0 &&
            thrust_ * R_(2, 2) <= Trajectory::kGravity_m_s2;
  crashed_ = false;
}

void QuadrotorDynamics::setCommand(const QuadrotorCommand& command) {
  cmd_.thrust_m_s2 = std::clamp(std::isfinite(command.thrust_m_s2) ? command.thrust_m_s2 : 0.0, 0.0,
                                options_.max_thrust_m_s2);
  for (int i = 0; i < 3; ++i)
    cmd_.w_IinI(i) = std::clamp(std::isfinite(command.w_IinI(i)) ? command.w_IinI(i) : 0.0, -options_.max_rate_rad_s,
                                options_.max_rate_rad_s);
}

Eigen::Vector3d QuadrotorDynamics::acceleration(const Eigen::Matrix3d& R, double thrust,
                                                const Eigen::Vector3d& v) const {
  const Eigen::Vector3d g_G(0.0, 0.0, -Trajectory::kGravity_m_s2);
  return R.col(2) * thrust + g_G - options_.drag_per_s * (v - wind_G_);
}

void QuadrotorDynamics::step() {
  ++k_;
  if (crashed_) return;
  // Wind: the gust process (its draws only when gusts are on).
  if (options_.gust_sigma_m_s > 0.0) {
    const double rho = std::exp(-dt_ / options_.gust_time_constant_s);
    gust_G_ = rho * gust_G_ + std::sqrt(1.0 - rho * rho) * rng_wind_.gaussian3(options_.gust_sigma_m_s);
    wind_G_ = options_.wind_mean_m_s + gust_G_;
  }
  // Lags, exact over the step.
  const double e_T = std::exp(-dt_ / options_.thrust_time_constant_s);
  const double e_w = std::exp(-dt_ / options_.rate_time_constant_s);
  const double thrust_next = cmd_.thrust_m_s2 + (thrust_ - cmd_.thrust_m_s2) * e_T;
  const Eigen::Vector3d w_next = cmd_.w_IinI + (w_ - cmd_.w_IinI) * e_w;
  if (landed_) {
    // Resting: the floor holds it until the thrust's vertical part lifts it (rates held at 0).
    thrust_ = thrust_next;
    w_.setZero();
    if (thrust_ * R_(2, 2) > Trajectory::kGravity_m_s2) landed_ = false;
    return;
  }
  const Eigen::Vector3d a0 = acceleration(R_, thrust_, v_);
  const Eigen::Matrix3d R_next = R_ * expSO3(0.5 * (w_ + w_next) * dt_);
  // Velocity: trapezoid with the end's acceleration at the predicted velocity (drag is linear in v:
  // solve v1 = v0 + ½Δt (a0 + a(v1)) in closed form).
  const double kd = options_.drag_per_s;
  const Eigen::Vector3d a1_no_v = acceleration(R_next, thrust_next, Eigen::Vector3d::Zero());  // a(v) = a1_no_v − kd v
  const Eigen::Vector3d v_next = (v_ + 0.5 * dt_ * (a0 + a1_no_v)) / (1.0 + 0.5 * dt_ * kd);
  const Eigen::Vector3d a1 = a1_no_v - kd * v_next;
  p_ += v_ * dt_ + (2.0 * a0 + a1) * dt_ * dt_ / 6.0;
  v_ = v_next;
  R_ = R_next;
  // Keep R orthonormal against round-off.
  const Eigen::Quaterniond q(R_);
  R_ = q.normalized().toRotationMatrix();
  w_ = w_next;
  thrust_ = thrust_next;
  contact();
}

void QuadrotorDynamics::contact() {
  // Walls and ceiling.
  for (int i = 0; i < 3; ++i) {
    const bool below = i < 2 && p_(i) < options_.hall_min_m(i);
    const bool above = p_(i) > options_.hall_max_m(i);
    if (!below && !above) continue;
    const double speed = std::abs(v_(i));
    p_(i) = below ? options_.hall_min_m(i) : options_.hall_max_m(i);
    if (speed > options_.crash_speed_m_s) {
      crashed_ = true;
      crash_speed_ = speed;
      crash_reason_ = i == 2 ? "ceiling" : "wall";
      v_.setZero();
      w_.setZero();
      return;
    }
    v_(i) = 0.0;
  }
  // Floor.
  if (p_.z() < options_.pad_height_m) {
    const double speed = v_.norm();
    p_.z() = options_.pad_height_m;
    v_.setZero();
    w_.setZero();
    if (speed > options_.crash_speed_m_s) {
      crashed_ = true;
      crash_speed_ = speed;
      crash_reason_ = "floor";
      return;
    }
    R_ = levelled(R_);
    landed_ = thrust_ * R_(2, 2) <= Trajectory::kGravity_m_s2;
  }
}

void QuadrotorDynamics::stepUntil(double t_s) {
  while (time() + 0.5 * dt_ <= t_s) step();
}

TrajectoryState QuadrotorDynamics::state() const {
  TrajectoryState s;
  s.t_s = time();
  s.p_IinG = p_;
  s.v_IinG = v_;
  s.R_ItoG = R_;
  s.q_ItoG = Eigen::Quaterniond(R_).normalized();
  s.w_IinI = w_;
  s.yaw_rad = std::atan2(R_(1, 0), R_(0, 0));
  if (!landed_ && !crashed_) {
    s.a_IinG = acceleration(R_, thrust_, v_);
    s.alpha_IinI = (cmd_.w_IinI - w_) / options_.rate_time_constant_s;
  }
  return s;
}

}  // namespace meshnav::sim
