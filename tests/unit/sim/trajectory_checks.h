#pragma once
/// @file trajectory_checks.h
/// @brief Test helpers shared by the trajectory tests: a strapdown integrator (RK4) of IMU
/// samples and checks of a motion against the hall.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <vector>

#include "common/types.h"
#include "sim/hall.h"
#include "sim/imu_simulator.h"
#include "sim/trajectory.h"

namespace meshnav::sim::test {

/// Navigation state of the strapdown integration.
struct NavState {
  Eigen::Vector3d p, v;
  Eigen::Vector4d q;  ///< (w, x, y, z) of q_ItoG
};

inline Eigen::Quaterniond toQuat(const Eigen::Vector4d& q) { return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized(); }

/// ṗ = v, v̇ = R(q) f + g, q̇ = ½ q ⊗ [0, ω].
inline NavState navDerivative(const NavState& x, const Eigen::Vector3d& f, const Eigen::Vector3d& w) {
  const Eigen::Vector3d g(0, 0, -Trajectory::kGravity_m_s2);
  NavState d;
  d.p = x.v;
  d.v = toQuat(x.q) * f + g;
  const Eigen::Quaterniond q(x.q[0], x.q[1], x.q[2], x.q[3]);
  const Eigen::Quaterniond qw = q * Eigen::Quaterniond(0, w.x(), w.y(), w.z());
  d.q = 0.5 * Eigen::Vector4d(qw.w(), qw.x(), qw.y(), qw.z());
  return d;
}

inline NavState axpy(const NavState& x, double h, const NavState& d) { return {x.p + h * d.p, x.v + h * d.v, x.q + h * d.q}; }

/// RK4 over the samples [k0, k1] in steps of `stride` samples (1 or 2). With stride 2 the
/// mid-step input is the sample in between (exact); with stride 1 it is linearly interpolated.
inline NavState integrate(const std::vector<ImuSample>& imu, size_t k0, size_t k1, NavState x, size_t stride = 1) {
  for (size_t k = k0; k + stride <= k1; k += stride) {
    const ImuSample &a = imu[k], &b = imu[k + stride];
    const double h = (b.t - a.t).sec();
    const Eigen::Vector3d fm = stride == 2 ? imu[k + 1].acc_m_s2 : Eigen::Vector3d(0.5 * (a.acc_m_s2 + b.acc_m_s2));
    const Eigen::Vector3d wm = stride == 2 ? imu[k + 1].gyro_rad_s : Eigen::Vector3d(0.5 * (a.gyro_rad_s + b.gyro_rad_s));
    const NavState d1 = navDerivative(x, a.acc_m_s2, a.gyro_rad_s);
    const NavState d2 = navDerivative(axpy(x, h / 2, d1), fm, wm);
    const NavState d3 = navDerivative(axpy(x, h / 2, d2), fm, wm);
    const NavState d4 = navDerivative(axpy(x, h, d3), b.acc_m_s2, b.gyro_rad_s);
    x.p += h / 6 * (d1.p + 2 * d2.p + 2 * d3.p + d4.p);
    x.v += h / 6 * (d1.v + 2 * d2.v + 2 * d3.v + d4.v);
    x.q += h / 6 * (d1.q + 2 * d2.q + 2 * d3.q + d4.q);
    x.q.normalize();
  }
  return x;
}

inline NavState trueState(const TrajectoryState& s) {
  return {s.p_IinG, s.v_IinG, Eigen::Vector4d(s.q_ItoG.w(), s.q_ItoG.x(), s.q_ItoG.y(), s.q_ItoG.z())};
}

/// Largest errors of a noise-free dead reckoning over the whole motion.
struct DeadReckoningError {
  double position_m = 0.0, velocity_m_s = 0.0, attitude_rad = 0.0;
};

/// Simulates a zero-noise, zero-bias IMU at 400 Hz and integrates it with RK4 at 200 Hz (the odd
/// samples are the exact mid-step inputs) from the true initial state over the whole motion,
/// comparing with the truth every second.
inline DeadReckoningError deadReckon(const Trajectory& tr) {
  ImuNoiseOptions o = ImuNoiseOptions::noiseless();
  o.rate_hz = 400.0;
  ImuSimulator sim(o, 1);
  const auto imu = sim.simulate(tr, tr.duration());
  DeadReckoningError err;
  NavState x = trueState(tr.evaluate(0.0));
  for (size_t k = 0; k + 400 < imu.size(); k += 400) {
    x = integrate(imu, k, k + 400, x, 2);
    const TrajectoryState truth = tr.evaluate(imu[k + 400].t.sec());
    err.position_m = std::max(err.position_m, (x.p - truth.p_IinG).norm());
    err.velocity_m_s = std::max(err.velocity_m_s, (x.v - truth.v_IinG).norm());
    err.attitude_rad = std::max(err.attitude_rad, toQuat(x.q).angularDistance(truth.q_ItoG));
  }
  return err;
}

/// Smallest distances of the motion (sampled at 20 Hz) to the walls, floor and ceiling [m].
struct HallClearance {
  double walls_m = 1e9, floor_m = 1e9, ceiling_m = 1e9;
};

inline HallClearance clearance(const Trajectory& tr, const Hall& hall) {
  HallClearance c;
  for (double t = 0.0; t <= tr.duration(); t += 0.05) {
    const Eigen::Vector3d p = tr.evaluate(t).p_IinG;
    for (int i = 0; i < 2; ++i) c.walls_m = std::min({c.walls_m, p[i] - hall.min_m[i], hall.max_m[i] - p[i]});
    c.floor_m = std::min(c.floor_m, p.z() - hall.min_m.z());
    c.ceiling_m = std::min(c.ceiling_m, hall.max_m.z() - p.z());
  }
  return c;
}

/// The halls the tests fly in: the paper's, the smallest and the largest of the robustness sweep.
inline std::vector<Hall> testHalls() {
  return {Hall::paper(), Hall::ofSize({6.0, 6.0, 3.0}), Hall::ofSize({12.0, 9.0, 8.0}), Hall::ofSize({6.0, 12.0, 4.0})};
}

}  // namespace meshnav::sim::test
