#include "controller/waypoint_follower.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace meshnav::controller {

namespace {
constexpr double kDegToRad = std::numbers::pi / 180.0;

/// `yaw` moved by whole turns to within π of `ref`.
double unwrapNear(double yaw, double ref) {
  return ref + std::remainder(yaw - ref, 2.0 * std::numbers::pi);
}
}  // namespace

WaypointFollower::WaypointFollower(mission::FlightPlan plan) : plan_(std::move(plan)) {
  if (plan_.waypoints.empty()) throw std::invalid_argument("WaypointFollower: the flight plan has no waypoints");
}

const char* WaypointFollower::toString(Phase p) {
  switch (p) {
    case Phase::TakeOff: return "takeoff";
    case Phase::Waypoints: return "waypoints";
    case Phase::ReturnToPad: return "return";
    case Phase::Landing: return "landing";
  }
  return "?";
}

void WaypointFollower::buildLegs(const Eigen::Vector3d& p0, double yaw0) {
  legs_.clear();
  const double pad_yaw = plan_.pad_yaw_deg * kDegToRad;
  Leg up;
  up.a = p0;
  up.b = Eigen::Vector3d(p0.x(), p0.y(), plan_.takeoff_height_m);
  up.yaw_a = yaw0;
  up.yaw_b = yaw0;
  up.hold_s = 1.0;  // settle before the first leg
  up.waypoint = -1;
  legs_.push_back(up);
  for (size_t i = 0; i < plan_.waypoints.size(); ++i) {
    const auto& w = plan_.waypoints[i];
    Leg l;
    l.a = legs_.back().b;
    l.b = w.p_IinG;
    l.yaw_a = legs_.back().yaw_b;
    l.yaw_b = unwrapNear(w.yaw_deg * kDegToRad, l.yaw_a);
    l.hold_s = w.hold_s;
    l.waypoint = static_cast<int>(i);
    legs_.push_back(l);
  }
  Leg back;
  back.a = legs_.back().b;
  back.b = Eigen::Vector3d(plan_.pad_xy_m.x(), plan_.pad_xy_m.y(), plan_.takeoff_height_m);
  back.yaw_a = legs_.back().yaw_b;
  back.yaw_b = unwrapNear(pad_yaw, back.yaw_a);
  back.hold_s = 2.0;  // settle above the pad before the descent
  back.waypoint = static_cast<int>(plan_.waypoints.size());
  legs_.push_back(back);
  landing_p_ = back.b;
  landing_yaw_ = back.yaw_b;
}

void WaypointFollower::start(double t_s, const Eigen::Vector3d& p_IinG, double yaw_rad) {
  buildLegs(p_IinG, yaw_rad);
  leg_ = 0;
  leg_start_s_ = t_s;
}

void WaypointFollower::resumeFrom(double t_s, const Eigen::Vector3d& p_IinG, double yaw_rad) {
  leg_start_s_ = t_s;
  if (landing()) return;
  Leg& l = legs_[leg_];
  l.a = p_IinG;
  l.yaw_a = yaw_rad;
  l.yaw_b = unwrapNear(l.yaw_b, yaw_rad);
}

WaypointFollower::Profile WaypointFollower::profile(const Leg& leg) const {
  Profile p;
  p.length = (leg.b - leg.a).norm();
  const double vertical_share = p.length > 0.0 ? std::abs(leg.b.z() - leg.a.z()) / p.length : 0.0;
  p.v_max = plan_.speed_m_s;
  if (vertical_share * p.v_max > plan_.vertical_speed_m_s) p.v_max = plan_.vertical_speed_m_s / vertical_share;
  const double acc = plan_.acceleration_m_s2;
  if (p.length < p.v_max * p.v_max / acc) p.v_max = std::sqrt(p.length * acc);  // triangle
  p.t_ramp = p.v_max / acc;
  p.t_move = p.v_max > 0.0 ? p.length / p.v_max + p.t_ramp : 0.0;
  const double t_yaw = std::abs(leg.yaw_b - leg.yaw_a) / (plan_.yaw_rate_deg_s * kDegToRad);
  p.t_total = std::max(p.t_move, t_yaw) + leg.hold_s;
  return p;
}

Setpoint WaypointFollower::setpoint(double t_s) {
  while (!landing() && t_s - leg_start_s_ >= profile(legs_[leg_]).t_total) {
    leg_start_s_ += profile(legs_[leg_]).t_total;
    ++leg_;
  }
  Setpoint sp;
  if (landing()) {
    sp.p_IinG = landing_p_;
    sp.v_IinG = Eigen::Vector3d(0.0, 0.0, -plan_.vertical_speed_m_s);
    sp.yaw_rad = landing_yaw_;
    sp.hold_z = false;
    return sp;
  }
  const Leg& l = legs_[leg_];
  const Profile pr = profile(l);
  const double tau = std::max(0.0, t_s - leg_start_s_);
  const double acc = plan_.acceleration_m_s2;
  double s = 0.0, ds = 0.0, dds = 0.0;
  if (pr.length > 0.0) {
    if (tau < pr.t_ramp) {
      s = 0.5 * acc * tau * tau;
      ds = acc * tau;
      dds = acc;
    } else if (tau < pr.t_move - pr.t_ramp) {
      s = pr.v_max * tau - 0.5 * pr.v_max * pr.t_ramp;
      ds = pr.v_max;
    } else if (tau < pr.t_move) {
      const double r = pr.t_move - tau;
      s = pr.length - 0.5 * acc * r * r;
      ds = acc * r;
      dds = -acc;
    } else {
      s = pr.length;
    }
  }
  const Eigen::Vector3d u = pr.length > 0.0 ? Eigen::Vector3d((l.b - l.a) / pr.length) : Eigen::Vector3d::Zero();
  sp.p_IinG = l.a + s * u;
  sp.v_IinG = ds * u;
  sp.a_IinG = dds * u;
  const double t_turn = pr.t_total - l.hold_s;
  sp.yaw_rad = t_turn > 0.0 ? l.yaw_a + (l.yaw_b - l.yaw_a) * std::min(1.0, tau / t_turn) : l.yaw_b;
  return sp;
}

WaypointFollower::Phase WaypointFollower::phase() const {
  if (landing()) return Phase::Landing;
  if (leg_ == 0) return Phase::TakeOff;
  if (leg_ + 1 == legs_.size()) return Phase::ReturnToPad;
  return Phase::Waypoints;
}

int WaypointFollower::waypointIndex() const {
  return landing() ? static_cast<int>(plan_.waypoints.size()) : legs_[leg_].waypoint;
}

}  // namespace meshnav::controller
