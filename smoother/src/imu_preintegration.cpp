/// @file imu_preintegration.cpp
/// @brief Preintegrated IMU increments (imu_preintegration.h).

#include "smoother/imu_preintegration.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "common/skew.h"
#include "estimator/core/so3.h"

namespace meshnav::smoother {

namespace {

/// Index of the first sample at or after `t`.
size_t firstAtOrAfter(const std::vector<ImuSample>& imu, Timestamp t) {
  return static_cast<size_t>(
      std::lower_bound(imu.begin(), imu.end(), t, [](const ImuSample& s, Timestamp x) { return s.t < x; }) -
      imu.begin());
}

}  // namespace

ImuSample interpolateImu(const std::vector<ImuSample>& imu, Timestamp t) {
  if (imu.empty()) throw std::invalid_argument("interpolateImu: no IMU samples");
  const size_t j = firstAtOrAfter(imu, t);
  if (j == 0) return ImuSample{t, imu.front().acc_m_s2, imu.front().gyro_rad_s};
  if (j >= imu.size()) return ImuSample{t, imu.back().acc_m_s2, imu.back().gyro_rad_s};
  const ImuSample& a = imu[j - 1];
  const ImuSample& b = imu[j];
  const double span = (b.t - a.t).sec();
  const double w = span > 0.0 ? (t - a.t).sec() / span : 0.0;
  return ImuSample{t, (1.0 - w) * a.acc_m_s2 + w * b.acc_m_s2, (1.0 - w) * a.gyro_rad_s + w * b.gyro_rad_s};
}

ImuIncrement preintegrate(const std::vector<ImuSample>& imu, Timestamp t0, Timestamp t1, const Eigen::Vector3d& bg,
                          const Eigen::Vector3d& ba, const ImuNoiseDensities& noise) {
  if (t1 < t0) throw std::invalid_argument("preintegrate: end before start");
  if (imu.empty() || imu.front().t > t0 || imu.back().t < t1)
    throw std::invalid_argument("preintegrate: the IMU samples do not cover [" + std::to_string(t0.sec()) + ", " +
                                std::to_string(t1.sec()) + "] s");
  using estimator::so3::expMap;
  using estimator::so3::rightJacobian;
  ImuIncrement inc;
  inc.dt_s = (t1 - t0).sec();
  inc.bg_lin = bg;
  inc.ba_lin = ba;
  const double var_g = noise.gyro * noise.gyro, var_a = noise.acc * noise.acc;
  ImuSample prev = interpolateImu(imu, t0);
  size_t j = firstAtOrAfter(imu, t0);
  if (j < imu.size() && imu[j].t == t0) ++j;
  while (prev.t < t1) {
    const ImuSample next = (j < imu.size() && imu[j].t < t1) ? imu[j] : interpolateImu(imu, t1);
    ++j;
    const double d = (next.t - prev.t).sec();
    if (d <= 0.0) {
      prev = next;
      continue;
    }
    // Inside an IMU gap (the samples around this sub-step farther apart than max_dt_s) the
    // interpolated readings carry the gap's noise as well.
    double vg = var_g, va = var_a;
    if (noise.max_dt_s > 0.0) {
      const size_t r = firstAtOrAfter(imu, next.t);
      if (r > 0 && r < imu.size() && (imu[r].t - imu[r - 1].t).sec() > noise.max_dt_s) {
        vg += noise.gap_gyro * noise.gap_gyro;
        va += noise.gap_acc * noise.gap_acc;
      }
    }
    const Eigen::Vector3d w = 0.5 * (prev.gyro_rad_s + next.gyro_rad_s) - bg;
    const Eigen::Vector3d a = 0.5 * (prev.acc_m_s2 + next.acc_m_s2) - ba;
    const Eigen::Matrix3d E = expMap(w * d);
    const Eigen::Matrix3d Jr = rightJacobian(w * d);
    const Eigen::Matrix3d Rm = inc.dR * expMap(0.5 * w * d);  // the step's mid attitude
    const Eigen::Matrix3d Ra = Rm * skew(a);
    // Covariance first (it needs the old ΔR).
    Eigen::Matrix<double, 9, 9> A = Eigen::Matrix<double, 9, 9>::Identity();
    A.block<3, 3>(0, 0) = E.transpose();
    A.block<3, 3>(3, 0) = -Ra * d;
    A.block<3, 3>(6, 0) = -0.5 * Ra * d * d;
    A.block<3, 3>(6, 3) = Eigen::Matrix3d::Identity() * d;
    Eigen::Matrix<double, 9, 3> Bg = Eigen::Matrix<double, 9, 3>::Zero(), Ba = Eigen::Matrix<double, 9, 3>::Zero();
    Bg.block<3, 3>(0, 0) = Jr * d;
    Ba.block<3, 3>(3, 0) = inc.dR * d;
    Ba.block<3, 3>(6, 0) = 0.5 * inc.dR * d * d;
    inc.cov = A * inc.cov * A.transpose() + Bg * (vg / d) * Bg.transpose() + Ba * (va / d) * Ba.transpose();
    // Sensitivities (p before v before R, each with the old values).
    inc.dp_dba += inc.dv_dba * d - 0.5 * Rm * d * d;
    inc.dp_dbg += inc.dv_dbg * d - 0.5 * Ra * inc.dR_dbg * d * d;
    inc.dv_dba -= Rm * d;
    inc.dv_dbg -= Ra * inc.dR_dbg * d;
    inc.dR_dbg = E.transpose() * inc.dR_dbg - Jr * d;
    // Increments, the specific force rotated by the step's mid attitude (second order in ω δ).
    const Eigen::Vector3d a_mid = Rm * a;
    inc.dp += inc.dv * d + 0.5 * a_mid * d * d;
    inc.dv += a_mid * d;
    inc.dR = inc.dR * E;
    prev = next;
  }
  inc.cov = 0.5 * (inc.cov + inc.cov.transpose());
  return inc;
}

}  // namespace meshnav::smoother
