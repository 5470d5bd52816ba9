/// @file convert.cpp
/// @brief Plain struct <-> LCM conversions of the measurements, the estimates and the
/// calibration (anchor init, pair biases), each decoded value checked finite and plausible.
/// Status and command messages are in convert_status.cpp.

#include "transport/convert.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

#include "common/plausibility.h"
#include "transport/src/convert_internals.h"

namespace meshnav::transport {
namespace {

using convert_internal::clampedCount;

void put3(const Eigen::Vector3d& v, double* out) {
  for (int i = 0; i < 3; ++i) out[i] = v[i];
}
Eigen::Vector3d get3(const double* in) { return Eigen::Vector3d(in[0], in[1], in[2]); }

/// Row-major: element (r, c) at 3r + c.
void put33(const Eigen::Matrix3d& m, double* out) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[3 * r + c] = m(r, c);
}
Eigen::Matrix3d get33(const double* in) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = in[3 * r + c];
  return m;
}

/// [w, x, y, z]
void putQ(const Eigen::Quaterniond& q, double* out) {
  out[0] = q.w();
  out[1] = q.x();
  out[2] = q.y();
  out[3] = q.z();
}
Eigen::Quaterniond getQ(const double* in) { return Eigen::Quaterniond(in[0], in[1], in[2], in[3]); }

template <size_t N>
void requireFinite(const double (&a)[N], const char* what) {
  for (size_t i = 0; i < N; ++i)
    if (!std::isfinite(a[i])) throw InvalidMessage(std::string("non-finite ") + what);
}
void requireFinite(double v, const char* what) {
  if (!std::isfinite(v)) throw InvalidMessage(std::string("non-finite ") + what);
}

/// Plausibility limits of common/plausibility.h on a decoded field (bad bytes behind a valid
/// fingerprint decode to anything).
void requireWithin(double v, double lo, double hi, const char* what) {
  if (!(v >= lo && v <= hi))
    throw InvalidMessage(std::string(what) + " " + std::to_string(v) + " outside the plausible [" + std::to_string(lo) +
                         ", " + std::to_string(hi) + "]");
}

/// A covariance as published: symmetric and positive semi-definite up to rounding (a negative
/// variance behind a valid fingerprint turned into NaN in the calibrator's sqrt).
void requireCovariance(const double (&a)[9], const char* what) {
  requireFinite(a, what);
  const Eigen::Matrix3d C = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(a);
  const double scale = 1.0 + C.cwiseAbs().maxCoeff();
  if ((C - C.transpose()).cwiseAbs().maxCoeff() > 1e-6 * scale)
    throw InvalidMessage(std::string(what) + " is not symmetric");
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(0.5 * (C + C.transpose()), Eigen::EigenvaluesOnly);
  if (es.eigenvalues().minCoeff() < -1e-9 * scale)
    throw InvalidMessage(std::string(what) + " is not positive semi-definite (smallest eigenvalue " +
                         std::to_string(es.eigenvalues().minCoeff()) + ")");
}

UwbType uwbTypeFromCode(int8_t code, const char* what) {
  if (code == range_t::TYPE_TAG) return UwbType::Tag;
  if (code == range_t::TYPE_ANCHOR) return UwbType::Anchor;
  throw InvalidMessage(std::string("unknown device type code ") + std::to_string(code) + " in " + what);
}

}  // namespace

// ---------------------------------------------------------------------------------- measurements

imu_t toLcm(const ImuSample& s) {
  imu_t m;
  m.sender_id = 0;  // set by LcmNode::publish
  m.utime = s.t.us;
  put3(s.acc_m_s2, m.lin_acc);
  put3(s.gyro_rad_s, m.ang_vel);
  return m;
}
ImuSample fromLcm(const imu_t& m) {
  requireFinite(m.lin_acc, "lin_acc");
  requireFinite(m.ang_vel, "ang_vel");
  ImuSample s;
  s.t = Timestamp::fromUtime(m.utime);
  s.acc_m_s2 = get3(m.lin_acc);
  s.gyro_rad_s = get3(m.ang_vel);
  requireWithin(s.acc_m_s2.norm(), 0.0, plausible::kMaxSpecificForce_m_s2, "|lin_acc| [m/s^2]");
  requireWithin(s.gyro_rad_s.norm(), 0.0, plausible::kMaxAngularRate_rad_s, "|ang_vel| [rad/s]");
  return s;
}

baro_t toLcm(const BaroSample& s) {
  baro_t m;
  m.sender_id = 0;  // set by LcmNode::publish
  m.utime = s.t.us;
  m.pressure = s.pressure_pa;
  return m;
}
height_t toLcm(const HeightSample& s) {
  height_t m;
  m.sender_id = 0;  // set by LcmNode::publish
  m.utime = s.t.us;
  m.range = s.range_m;
  return m;
}
HeightSample fromLcm(const height_t& m) {
  requireFinite(m.range, "range");
  requireWithin(m.range, 0.0, plausible::kMaxHeight_m, "range [m]");
  HeightSample s;
  s.t = Timestamp::fromUtime(m.utime);
  s.range_m = m.range;
  return s;
}
BaroSample fromLcm(const baro_t& m) {
  requireFinite(m.pressure, "pressure");
  requireWithin(m.pressure, plausible::kMinPressure_pa, plausible::kMaxPressure_pa, "pressure [Pa]");
  BaroSample s;
  s.t = Timestamp::fromUtime(m.utime);
  s.pressure_pa = m.pressure;
  return s;
}

range_t toLcm(const RangeSample& s) {
  range_t m;
  m.sender_id = 0;  // set by LcmNode::publish
  m.utime = s.t.us;
  m.id_initiator = s.id_initiator;
  m.id_responder = s.id_responder;
  m.type_initiator = static_cast<int8_t>(s.type_initiator);
  m.type_responder = static_cast<int8_t>(s.type_responder);
  m.range = s.range_m;
  m.range_corr = s.range_corr_m;
  m.variance = s.R_m2;
  m.los = s.los;
  return m;
}
RangeSample fromLcm(const range_t& m) {
  requireFinite(m.range, "range");
  requireFinite(m.range_corr, "range_corr");
  requireFinite(m.variance, "variance");
  requireWithin(m.range, plausible::kMinRange_m, plausible::kMaxRange_m, "range [m]");
  requireWithin(m.range_corr, plausible::kMinRange_m, plausible::kMaxRange_m, "range_corr [m]");
  requireWithin(m.variance, 0.0, plausible::kMaxRangeVariance_m2, "variance [m^2]");
  RangeSample s;
  s.t = Timestamp::fromUtime(m.utime);
  s.id_initiator = m.id_initiator;
  s.id_responder = m.id_responder;
  s.type_initiator = uwbTypeFromCode(m.type_initiator, "type_initiator");
  s.type_responder = uwbTypeFromCode(m.type_responder, "type_responder");
  s.range_m = m.range;
  s.range_corr_m = m.range_corr;
  s.R_m2 = m.variance;
  s.los = m.los;
  return s;
}

flight_state_t toLcm(const FlightStateSample& s) {
  flight_state_t m;
  m.sender_id = 0;  // set by LcmNode::publish
  m.utime = s.t.us;
  m.landed = s.landed;
  return m;
}
FlightStateSample fromLcm(const flight_state_t& m) {
  FlightStateSample s;
  s.t = Timestamp::fromUtime(m.utime);
  s.landed = m.landed;
  return s;
}

ground_truth_t toLcm(const PoseSample& s) {
  ground_truth_t m;
  m.sender_id = 0;  // set by LcmNode::publish
  m.utime = s.t.us;
  put3(s.p_IinG, m.p_IinG);
  putQ(s.q_ItoG, m.q_ItoG);
  return m;
}
PoseSample fromLcm(const ground_truth_t& m) {
  requireFinite(m.p_IinG, "p_IinG");
  requireFinite(m.q_ItoG, "q_ItoG");
  PoseSample s;
  s.t = Timestamp::fromUtime(m.utime);
  s.p_IinG = get3(m.p_IinG);
  s.q_ItoG = getQ(m.q_ItoG);
  return s;
}

// ------------------------------------------------------------------------------------- estimates

pose_t toLcm(const PoseEstimate& s) {
  pose_t m;
  m.sender_id = 0;  // set by LcmNode::publish
  m.utime = s.t.us;
  put3(s.p_IinG, m.p_IinG);
  put3(s.v_IinG, m.v_IinG);
  putQ(s.q_ItoG, m.q_ItoG);
  put3(s.bias_gyro_rad_s, m.bias_gyro);
  put3(s.bias_acc_m_s2, m.bias_acc);
  put33(s.cov_p_m2, m.cov_p);
  put33(s.cov_v, m.cov_v);
  put33(s.cov_theta_rad2, m.cov_theta);
  return m;
}
PoseEstimate fromLcm(const pose_t& m) {
  for (const auto* f : {&m.p_IinG, &m.v_IinG, &m.bias_gyro, &m.bias_acc}) requireFinite(*f, "pose_t vector");
  requireFinite(m.q_ItoG, "q_ItoG");
  requireWithin(std::sqrt(m.q_ItoG[0] * m.q_ItoG[0] + m.q_ItoG[1] * m.q_ItoG[1] + m.q_ItoG[2] * m.q_ItoG[2] +
                          m.q_ItoG[3] * m.q_ItoG[3]),
                1.0 - 1e-3, 1.0 + 1e-3, "|q_ItoG|");
  requireCovariance(m.cov_p, "cov_p");
  requireCovariance(m.cov_v, "cov_v");
  requireCovariance(m.cov_theta, "cov_theta");
  PoseEstimate s;
  s.t = Timestamp::fromUtime(m.utime);
  s.p_IinG = get3(m.p_IinG);
  s.v_IinG = get3(m.v_IinG);
  s.q_ItoG = getQ(m.q_ItoG);
  s.bias_gyro_rad_s = get3(m.bias_gyro);
  s.bias_acc_m_s2 = get3(m.bias_acc);
  s.cov_p_m2 = get33(m.cov_p);
  s.cov_v = get33(m.cov_v);
  s.cov_theta_rad2 = get33(m.cov_theta);
  return s;
}

peer_range_t toLcm(const PeerRange& s) {
  peer_range_t m;
  m.sender_id = 0;  // set by LcmNode::publish
  m.utime = s.t.us;
  m.range = toLcm(s.range);
  m.peer_tag = s.peer_tag;
  put3(s.p_peer_tag_in_G, m.p_peer_tag_in_G);
  put33(s.cov_peer_tag_m2, m.cov_peer_tag);
  return m;
}
PeerRange fromLcm(const peer_range_t& m) {
  requireFinite(m.p_peer_tag_in_G, "p_peer_tag_in_G");
  requireCovariance(m.cov_peer_tag, "cov_peer_tag");
  if (m.range.utime != m.utime) throw InvalidMessage("utime differs from range.utime");
  if (m.peer_tag != m.range.id_initiator && m.peer_tag != m.range.id_responder)
    throw InvalidMessage("peer_tag " + std::to_string(m.peer_tag) + " is no end of the range");
  PeerRange s;
  s.t = Timestamp::fromUtime(m.utime);
  s.range = fromLcm(m.range);
  s.peer_tag = m.peer_tag;
  s.p_peer_tag_in_G = get3(m.p_peer_tag_in_G);
  s.cov_peer_tag_m2 = get33(m.cov_peer_tag);
  return s;
}

anchor_estimate_t toLcm(const AnchorEstimate& s) {
  anchor_estimate_t m;
  m.utime = s.t.us;
  m.id = s.id;
  put3(s.p_AinG, m.p_AinG);
  put33(s.cov_p_m2, m.cov_p);
  return m;
}
AnchorEstimate fromLcm(const anchor_estimate_t& m) {
  requireFinite(m.p_AinG, "p_AinG");
  requireCovariance(m.cov_p, "cov_p");
  AnchorEstimate s;
  s.t = Timestamp::fromUtime(m.utime);
  s.id = m.id;
  s.p_AinG = get3(m.p_AinG);
  s.cov_p_m2 = get33(m.cov_p);
  return s;
}

anchors_t toLcm(Timestamp t, const std::vector<AnchorEstimate>& anchors) {
  anchors_t m;
  m.sender_id = 0;  // set by LcmNode::publish
  m.utime = t.us;
  m.num_anchors = clampedCount(anchors);
  for (int i = 0; i < m.num_anchors; ++i) m.anchors.push_back(toLcm(anchors[i]));
  return m;
}
anchors_t toLcm(const std::vector<AnchorEstimate>& anchors) {
  Timestamp t{0};
  for (const auto& a : anchors) t = std::max(t, a.t);
  return toLcm(t, anchors);
}
std::vector<AnchorEstimate> fromLcm(const anchors_t& m) {
  std::vector<AnchorEstimate> out;
  out.reserve(m.anchors.size());
  for (const auto& a : m.anchors) out.push_back(fromLcm(a));
  return out;
}

// ----------------------------------------------------------------------------------- calibration

pair_bias_t toLcm(const PairBias& s) {
  pair_bias_t m;
  m.a = s.a;
  m.b = s.b;
  m.gamma = s.gamma_m;
  m.beta = s.beta;
  m.sigma = s.sigma_m;
  m.sigma_gamma = s.sigma_gamma_m;
  m.sigma_beta = s.sigma_beta;
  return m;
}
PairBias fromLcm(const pair_bias_t& m) {
  requireFinite(m.gamma, "gamma");
  requireFinite(m.beta, "beta");
  requireFinite(m.sigma, "sigma");
  requireFinite(m.sigma_gamma, "sigma_gamma");
  requireFinite(m.sigma_beta, "sigma_beta");
  PairBias s;
  s.a = m.a;
  s.b = m.b;
  s.gamma_m = m.gamma;
  s.beta = m.beta;
  s.sigma_m = m.sigma;
  s.sigma_gamma_m = m.sigma_gamma;
  s.sigma_beta = m.sigma_beta;
  return s;
}

anchor_init_t toLcm(const AnchorInit& s) {
  anchor_init_t m;
  m.sender_id = 0;  // set by LcmNode::publish
  m.utime = s.t.us;
  m.id = s.id;
  put3(s.p_AinG, m.p_AinG);
  put33(s.cov_p_m2, m.cov_p);
  m.num_biases = clampedCount(s.biases);
  for (int i = 0; i < m.num_biases; ++i) m.biases.push_back(toLcm(s.biases[i]));
  m.num_inliers = s.n_inliers;
  m.num_outliers = s.n_outliers;
  if (const std::string bad = s.jointCovarianceError(); !bad.empty())
    throw std::invalid_argument("AnchorInit of anchor " + std::to_string(s.id) + ": " + bad);
  m.num_gamma_cov = s.hasJointCovariance() ? m.num_biases : 0;
  for (int i = 0; i < m.num_gamma_cov; ++i) {
    m.cov_gamma_p.push_back({s.cov_gamma_p_m2(i, 0), s.cov_gamma_p_m2(i, 1), s.cov_gamma_p_m2(i, 2)});
    std::vector<double> row(static_cast<size_t>(m.num_gamma_cov));
    for (int j = 0; j < m.num_gamma_cov; ++j) row[static_cast<size_t>(j)] = s.cov_gamma_m2(i, j);
    m.cov_gamma.push_back(std::move(row));
  }
  return m;
}
AnchorInit fromLcm(const anchor_init_t& m) {
  requireFinite(m.p_AinG, "p_AinG");
  requireFinite(m.cov_p, "cov_p");
  AnchorInit s;
  s.t = Timestamp::fromUtime(m.utime);
  s.id = m.id;
  s.p_AinG = get3(m.p_AinG);
  s.cov_p_m2 = get33(m.cov_p);
  for (const auto& b : m.biases) s.biases.push_back(fromLcm(b));
  s.n_inliers = m.num_inliers;
  s.n_outliers = m.num_outliers;
  if (m.num_gamma_cov != 0 && m.num_gamma_cov != m.num_biases)
    throw InvalidMessage("num_gamma_cov " + std::to_string(m.num_gamma_cov) + " is neither 0 nor num_biases " +
                         std::to_string(m.num_biases));
  const int n = m.num_gamma_cov;
  if (n > 0) {
    s.cov_gamma_p_m2.resize(n, 3);
    s.cov_gamma_m2.resize(n, n);
    for (int i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) {
        const double v = m.cov_gamma_p[static_cast<size_t>(i)][static_cast<size_t>(c)];
        requireFinite(v, "cov_gamma_p");
        s.cov_gamma_p_m2(i, c) = v;
      }
      for (int j = 0; j < n; ++j) {
        const double v = m.cov_gamma[static_cast<size_t>(i)][static_cast<size_t>(j)];
        requireFinite(v, "cov_gamma");
        s.cov_gamma_m2(i, j) = v;
      }
    }
  }
  return s;
}

}  // namespace meshnav::transport
