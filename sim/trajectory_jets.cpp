#include "sim/trajectory_jets.h"

#include <algorithm>

#include "sim/trajectory.h"

namespace meshnav::sim {

namespace {

using Jet3R = std::array<AttitudeJet, 3>;

Jet3R cross(const Jet3R& a, const Jet3R& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

Jet3R normalized(const Jet3R& a) {
  const AttitudeJet n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  return {a[0] / n, a[1] / n, a[2] / n};
}

Eigen::Vector3d vee(const Eigen::Matrix3d& S) {
  // Skew part only: robust against round-off in the symmetric part.
  return 0.5 * Eigen::Vector3d(S(2, 1) - S(1, 2), S(0, 2) - S(2, 0), S(1, 0) - S(0, 1));
}

/// Position, velocity and acceleration from the position jets.
TrajectoryState translationalState(double t_s, const PositionJet3& p) {
  TrajectoryState st;
  st.t_s = t_s;
  for (int i = 0; i < 3; ++i) {
    st.p_IinG[i] = p[i].derivative(0);
    st.v_IinG[i] = p[i].derivative(1);
    st.a_IinG[i] = p[i].derivative(2);
  }
  return st;
}

/// Fills R, q, ω, α of `st` from the columns [x_I y_I z_I] of R_ItoG as jets.
void setAttitude(TrajectoryState& st, const Jet3R& x_I, const Jet3R& y_I, const Jet3R& z_I) {
  Eigen::Matrix3d R, R_dot, R_ddot;
  const std::array<const Jet3R*, 3> cols{&x_I, &y_I, &z_I};
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) {
      R(r, c) = (*cols[c])[r].derivative(0);
      R_dot(r, c) = (*cols[c])[r].derivative(1);
      R_ddot(r, c) = (*cols[c])[r].derivative(2);
    }
  }
  st.R_ItoG = R;
  st.q_ItoG = Eigen::Quaterniond(R).normalized();
  st.w_IinI = vee(R.transpose() * R_dot);
  st.alpha_IinI = vee(R_dot.transpose() * R_dot + R.transpose() * R_ddot);
}

}  // namespace

PositionJet smoothStep(const PositionJet& u) {
  if (u.value() <= 0.0) return PositionJet::constant(0.0);
  if (u.value() >= 1.0) return PositionJet::constant(1.0);
  const PositionJet u2 = u * u;
  const PositionJet u5 = u2 * u2 * u;
  const PositionJet poly = 126.0 + u * (-420.0 + u * (540.0 + u * (-315.0 + 70.0 * u)));
  return u5 * poly;
}

PositionJet smoothStepIntegral(const PositionJet& u) {
  if (u.value() <= 0.0) return PositionJet::constant(0.0);
  if (u.value() >= 1.0) return u - 0.5;
  const PositionJet u3 = u * u * u;
  const PositionJet u6 = u3 * u3;
  const PositionJet poly = 21.0 + u * (-60.0 + u * (67.5 + u * (-35.0 + 7.0 * u)));
  return u6 * poly;
}

TrajectoryState quadrotorState(double t_s, const PositionJet3& p, const PositionJet& yaw_rad) {
  TrajectoryState st = translationalState(t_s, p);
  st.yaw_rad = yaw_rad.value();
  // Attitude from the thrust direction and the heading, as jets of order 2 in t.
  Jet3R thrust{p[0].derived<2>(), p[1].derived<2>(), p[2].derived<2>()};
  thrust[2] = thrust[2] + Trajectory::kGravity_m_s2;  // a − g_G
  const Jet3R z_I = normalized(thrust);
  AttitudeJet sin_psi, cos_psi;
  sincos(yaw_rad.truncated<kAttitudeJetOrder>(), sin_psi, cos_psi);
  const Jet3R x_c{cos_psi, sin_psi, AttitudeJet::constant(0.0)};
  const Jet3R y_I = normalized(cross(z_I, x_c));
  const Jet3R x_I = cross(y_I, z_I);
  setAttitude(st, x_I, y_I, z_I);
  return st;
}

TrajectoryState yawPitchRollState(double t_s, const PositionJet3& p, const PositionJet& yaw_rad,
                                  const PositionJet& pitch_rad, const PositionJet& roll_rad) {
  TrajectoryState st = translationalState(t_s, p);
  st.yaw_rad = yaw_rad.value();
  AttitudeJet sy, cy, sp, cp, sr, cr;
  sincos(yaw_rad.truncated<kAttitudeJetOrder>(), sy, cy);
  sincos(pitch_rad.truncated<kAttitudeJetOrder>(), sp, cp);
  sincos(roll_rad.truncated<kAttitudeJetOrder>(), sr, cr);
  // Columns of R_z(ψ) R_y(θ) R_x(φ).
  const Jet3R x_I{cy * cp, sy * cp, -sp};
  const Jet3R y_I{cy * sp * sr - sy * cr, sy * sp * sr + cy * cr, cp * sr};
  const Jet3R z_I{cy * sp * cr + sy * sr, sy * sp * cr - cy * sr, cp * cr};
  setAttitude(st, x_I, y_I, z_I);
  return st;
}

HallAxes HallAxes::of(const Hall& hall) {
  const Eigen::Vector3d size = hall.size();
  const bool x_long = size.x() >= size.y();
  HallAxes a;
  a.u = x_long ? Eigen::Vector2d::UnitX() : Eigen::Vector2d::UnitY();
  a.w = x_long ? Eigen::Vector2d::UnitY() : Eigen::Vector2d::UnitX();
  a.half_u_m = 0.5 * std::max(size.x(), size.y());
  a.half_w_m = 0.5 * std::min(size.x(), size.y());
  return a;
}

std::array<PositionJet, 2> HallAxes::point(const Eigen::Vector3d& c, const PositionJet& a, const PositionJet& b) const {
  return {c.x() + u.x() * a + w.x() * b, c.y() + u.y() * a + w.y() * b};
}

HeadingWobble HeadingWobble::draw(RandomStream& rng, double amplitude_lo, double amplitude_hi, double period_lo,
                                  double period_hi) {
  HeadingWobble h;
  h.yaw0_rad = rng.uniform(-kPi, kPi);
  h.amplitude_rad = rng.uniform(amplitude_lo, amplitude_hi);
  h.period_s = rng.uniform(period_lo, period_hi);
  h.phase_rad = rng.uniform(-kPi, kPi);
  return h;
}

PositionJet HeadingWobble::at(const PositionJet& t) const {
  return yaw0_rad + amplitude_rad * sin(t * (2.0 * kPi / period_s) + phase_rad);
}

PositionJet HeadingWobble::at(const PositionJet& t, const PositionJet& envelope) const {
  return yaw0_rad + amplitude_rad * (envelope * sin(t * (2.0 * kPi / period_s) + phase_rad));
}

}  // namespace meshnav::sim
