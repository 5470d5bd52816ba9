/// @file motion_aligner.cpp
/// @brief MotionAligner, first part: the window (IMU, ranges, heights), the strapdown increments
/// and the observation model (residuals and analytic Jacobians of ranges and heights). The fit
/// (starts, Levenberg–Marquardt, covariance and acceptance) is in motion_aligner_fit.cpp.

#include "estimator/init/motion_aligner.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "estimator/core/so3.h"
#include "estimator/init/motion_aligner_internals.h"

namespace meshnav::estimator {

namespace {

using motion_aligner_internal::kBh;
using motion_aligner_internal::VecU;

constexpr size_t kMaxObservations = 400;
constexpr size_t kMaxHeights = 200;

/// Increments advanced by δ seconds with held body readings f, ω.
MotionAligner::Increments advance(const MotionAligner::Increments& a, const Eigen::Vector3d& f,
                                  const Eigen::Vector3d& w, double dt) {
  MotionAligner::Increments b;
  const Eigen::Matrix3d Cm = a.C * so3::expMap(0.5 * dt * w);  // attitude at mid-step
  b.V = a.V + Cm * f * dt;
  b.S = a.S + a.V * dt + 0.5 * Cm * f * dt * dt;
  b.N = a.N + Cm * dt;
  b.M = a.M + a.N * dt + 0.5 * Cm * dt * dt;
  b.C = a.C * so3::expMap(dt * w);
  // Sensitivities to the gyro bias (ω = ω_m − b_ω): δφ' = Exp(ω dt)ᵀ δφ − J_r(ω dt) dt δb_ω,
  // δV' = δV − Ĉ[f]× δφ dt, δS' = δS + δV dt − ½ Ĉ[f]× δφ dt².
  const Eigen::Matrix3d Cf = a.C * so3::skew(f);
  b.JV = a.JV - Cf * a.JC * dt;
  b.JS = a.JS + a.JV * dt - 0.5 * Cf * a.JC * dt * dt;
  b.JC = so3::expMap(dt * w).transpose() * a.JC - so3::rightJacobian(dt * w) * dt;
  b.tau_s = a.tau_s + dt;
  return b;
}


}  // namespace

MotionAligner::Unknowns MotionAligner::Unknowns::plus(const VecU& d) const {
  Unknowns x = *this;
  x.p0 += d.segment<3>(0);
  x.v0 += d.segment<3>(3);
  x.R0 = R0 * so3::expMap(d.segment<3>(6));
  x.ba += d.segment<3>(9);
  x.dbg += d.segment<3>(12);
  x.bh += d(kBh);
  return x;
}

Eigen::Matrix3d MotionAligner::attitude(const Increments& inc, const Unknowns& x) {
  return inc.C * so3::expMap(inc.JC * x.dbg);
}

Eigen::Vector3d MotionAligner::bodyTerm(const Increments& inc, const Unknowns& x, const Eigen::Vector3d& p_TinI,
                                        const Eigen::Matrix3d& C) {
  return inc.S + inc.JS * x.dbg - inc.M * x.ba + C * p_TinI;
}

MotionAligner::MotionAligner(const MotionAlignerOptions& options, std::map<SensorId, Eigen::Vector3d> tags_p_TinI)
    : options_(options), tags_p_TinI_(std::move(tags_p_TinI)) {}

void MotionAligner::addImu(const ImuSample& s) {
  if (!imu_.empty() && s.t <= imu_.back().t) return;
  if (!imu_.empty() && (s.t - imu_.back().t).sec() > options_.max_imu_gap_s) clear();
  imu_.push_back(s);
  const Timestamp oldest = s.t - Duration::fromSec(options_.max_window_s);
  while (!imu_.empty() && imu_.front().t < oldest) imu_.pop_front();
  while (!ranges_.empty() && ranges_.front().t < oldest) ranges_.pop_front();
  while (!heights_.empty() && heights_.front().t < oldest) heights_.pop_front();
}

void MotionAligner::addHeight(const AlignHeight& h) {
  auto pos = std::upper_bound(heights_.begin(), heights_.end(), h.t,
                              [](Timestamp t, const AlignHeight& x) { return t < x.t; });
  heights_.insert(pos, h);
}

Timestamp MotionAligner::windowStart() const {
  if (imu_.empty()) return Timestamp{};
  const Timestamp end = imu_.back().t;
  Timestamp start = end - Duration::fromSec(options_.window_s);
  // Ranges up to the newest IMU sample, newest first: the window must hold `min_ranges` of them.
  std::vector<Timestamp> times;
  for (auto r = ranges_.rbegin(); r != ranges_.rend(); ++r)
    if (r->t <= end) times.push_back(r->t);
  const size_t need = static_cast<size_t>(std::max(options_.min_ranges, 1));
  if (times.size() >= need && times[need - 1] >= start) return std::max(start, imu_.front().t);
  // Sparse: back to the IMU sample at or before the `min_ranges`-th newest range (or all held).
  const Timestamp oldest = end - Duration::fromSec(options_.max_window_s);
  const Timestamp want = times.size() >= need ? times[need - 1] : oldest;
  auto it = std::upper_bound(imu_.begin(), imu_.end(), want, [](Timestamp t, const ImuSample& s) { return t < s.t; });
  if (it != imu_.begin()) --it;
  return std::max(it->t, imu_.front().t);
}

void MotionAligner::addRange(const AlignRange& r) {
  if (!tags_p_TinI_.count(r.tag)) return;
  auto pos = std::upper_bound(ranges_.begin(), ranges_.end(), r.t,
                              [](Timestamp t, const AlignRange& x) { return t < x.t; });
  ranges_.insert(pos, r);
}

void MotionAligner::clear() {
  imu_.clear();
  ranges_.clear();
  heights_.clear();
  last_fit_.reset();
}

double MotionAligner::spanSeconds() const { return imu_.size() < 2 ? 0.0 : (imu_.back().t - windowStart()).sec(); }

std::vector<MotionAligner::Obs> MotionAligner::buildObservations(const Eigen::Vector3d& bias_gyro, Increments* end,
                                                                 std::vector<HeightObs>* heights) const {
  std::vector<Obs> obs;
  heights->clear();
  Increments inc;
  const Timestamp t0 = windowStart();
  size_t k = 0;
  while (k + 1 < imu_.size() && imu_[k].t < t0) ++k;
  auto r = ranges_.begin();
  while (r != ranges_.end() && r->t < imu_[k].t) ++r;
  auto h = heights_.begin();
  while (h != heights_.end() && h->t < imu_[k].t) ++h;
  for (; k + 1 < imu_.size(); ++k) {
    const ImuSample &a = imu_[k], &b = imu_[k + 1];
    const Eigen::Vector3d f = 0.5 * (a.acc_m_s2 + b.acc_m_s2);
    const Eigen::Vector3d w = 0.5 * (a.gyro_rad_s + b.gyro_rad_s) - bias_gyro;
    for (; r != ranges_.end() && r->t < b.t; ++r) obs.push_back({*r, advance(inc, f, w, (r->t - a.t).sec()), true});
    for (; h != heights_.end() && h->t < b.t; ++h) heights->push_back({*h, advance(inc, f, w, (h->t - a.t).sec()), true});
    inc = advance(inc, f, w, (b.t - a.t).sec());
  }
  *end = inc;
  if (heights->size() > kMaxHeights) {
    std::vector<HeightObs> thin;
    const double step = static_cast<double>(heights->size()) / kMaxHeights;
    for (size_t i = 0; i < kMaxHeights; ++i) thin.push_back((*heights)[static_cast<size_t>(i * step)]);
    heights->swap(thin);
  }
  if (obs.size() > kMaxObservations) {  // evenly thinned: the cost of a fit stays bounded
    std::vector<Obs> thin;
    const double step = static_cast<double>(obs.size()) / kMaxObservations;
    for (size_t i = 0; i < kMaxObservations; ++i) thin.push_back(obs[static_cast<size_t>(i * step)]);
    obs.swap(thin);
  }
  return obs;
}

double MotionAligner::residual(const Obs& o, const Unknowns& x, Eigen::Matrix<double, 1, 16>* J) const {
  // r = d − ‖p_A − p_T‖: ∂r/∂p_T = uᵀ with u the unit vector from the tag to the anchor;
  // ∂p_T/∂[p₀, v₀, δθ, b_a, δb_ω] = [I, τ I, −R₀[w]×, −R₀ M, R₀ (J_S − C[p_TinI]× J_C)],
  // w = S − M b_a + C p_TinI (the J_C term to first order around the current δb_ω).
  const Eigen::Vector3d g = gravityG();
  const double tau = o.inc.tau_s;
  const Eigen::Vector3d& lever = tags_p_TinI_.at(o.r.tag);
  const Eigen::Matrix3d C = attitude(o.inc, x);
  const Eigen::Vector3d w = bodyTerm(o.inc, x, lever, C);
  const Eigen::Vector3d p_TinG = x.p0 + x.v0 * tau + 0.5 * g * tau * tau + x.R0 * w;
  if (J) {
    const Eigen::Vector3d u = (o.r.p_AinG - p_TinG).normalized();
    (*J)(kBh) = 0.0;
    J->segment<3>(0) = u.transpose();
    J->segment<3>(3) = tau * u.transpose();
    J->segment<3>(6) = -u.transpose() * x.R0 * so3::skew(w);
    J->segment<3>(9) = -u.transpose() * x.R0 * o.inc.M;
    J->segment<3>(12) = u.transpose() * x.R0 * (o.inc.JS - C * so3::skew(lever) * o.inc.JC);
  }
  return o.r.d_m - (o.r.p_AinG - p_TinG).norm();
}

double MotionAligner::residual(const HeightObs& o, const Unknowns& x, Eigen::Matrix<double, 1, 16>* J) const {
  // ĥ = s_z / c + b_H with s = p₀ + v₀τ + ½gτ² + R₀ w (w as for a tag, lever p_IH), c = e_zᵀ R₀ C e_z:
  // ∂s_z = e_zᵀ [I, τ I, −R₀[w]×, −R₀ M, R₀ (J_S − C[p_IH]× J_C)],
  // ∂c/∂δθ = −e_zᵀ R₀ [C e_z]×, ∂c/∂δb_ω = −e_zᵀ R₀ C [e_z]× J_C; r = h − ĥ, so J = −∂ĥ.
  const Eigen::Vector3d g = gravityG();
  const double tau = o.inc.tau_s;
  const Eigen::Vector3d& lever = options_.p_IH;
  const Eigen::Matrix3d E = so3::expMap(o.inc.JC * x.dbg);
  const Eigen::Matrix3d C = o.inc.C * E;  // attitude(o.inc, x)
  const Eigen::Vector3d w = bodyTerm(o.inc, x, lever, C);
  const Eigen::Vector3d s = x.p0 + x.v0 * tau + 0.5 * g * tau * tau + x.R0 * w;
  // c in the residual as (R₀ C_inc) E and in the Jacobian as R₀ (C_inc E): the same number up to
  // rounding, each kept as it was computed before the two functions were merged (same results).
  const double c = options_.height_tilt_correction ? (x.R0 * o.inc.C * E)(2, 2) : 1.0;
  if (J) {
    const Eigen::RowVector3d ez = Eigen::RowVector3d::UnitZ();
    Eigen::Matrix<double, 1, 15> ds;
    ds.segment<3>(0) = ez;
    ds.segment<3>(3) = tau * ez;
    ds.segment<3>(6) = -ez * x.R0 * so3::skew(w);
    ds.segment<3>(9) = -ez * x.R0 * o.inc.M;
    ds.segment<3>(12) = ez * x.R0 * (o.inc.JS - C * so3::skew(lever) * o.inc.JC);
    Eigen::Matrix<double, 1, 15> dh = ds;
    if (options_.height_tilt_correction) {
      const double cj = (x.R0 * C)(2, 2);
      Eigen::Matrix<double, 1, 15> dc = Eigen::Matrix<double, 1, 15>::Zero();
      dc.segment<3>(6) = -ez * x.R0 * so3::skew(C * Eigen::Vector3d::UnitZ());
      dc.segment<3>(12) = -ez * x.R0 * C * so3::skew(Eigen::Vector3d::UnitZ()) * o.inc.JC;
      dh = ds / cj - s.z() / (cj * cj) * dc;
    }
    J->head<15>() = -dh;
    (*J)(kBh) = -1.0;
  }
  return o.h.range_m - (s.z() / c + x.bh);
}

}  // namespace meshnav::estimator
