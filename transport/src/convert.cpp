#include "transport/convert.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/plausibility.h"

namespace meshnav::transport {
namespace {

constexpr size_t kMaxArray = std::numeric_limits<int16_t>::max();  // wire counts are int16

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

/// A string field as received. LCM's encoder writes a string up to its first NUL but sizes the
/// message by the whole string, so a string holding a NUL would not convert back (the message
/// published would end in garbage): refused.
const std::string& text(const std::string& s, const char* what) {
  if (s.find('\0') != std::string::npos) throw InvalidMessage(std::string("NUL byte inside the text of ") + what);
  return s;
}

UwbType uwbTypeFromCode(int8_t code, const char* what) {
  if (code == range_t::TYPE_TAG) return UwbType::Tag;
  if (code == range_t::TYPE_ANCHOR) return UwbType::Anchor;
  throw InvalidMessage(std::string("unknown device type code ") + std::to_string(code) + " in " + what);
}

template <class T>
int16_t clampedCount(const std::vector<T>& v) {
  return static_cast<int16_t>(std::min(v.size(), kMaxArray));
}

std::vector<counter_t> countersToLcm(const std::map<std::string, int64_t>& m) {
  std::vector<counter_t> out;
  for (const auto& [name, value] : m) {
    if (out.size() == kMaxArray) break;
    counter_t c;
    c.name = name;
    c.value = value;
    out.push_back(c);
  }
  return out;
}
std::map<std::string, int64_t> countersFromLcm(const std::vector<counter_t>& v) {
  std::map<std::string, int64_t> m;
  for (const auto& c : v) m[text(c.name, "a counter name")] = c.value;
  return m;
}

}  // namespace

// ---------------------------------------------------------------------------------- measurements

imu_t toLcm(const ImuSample& s) {
  imu_t m;
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
  m.utime = s.t.us;
  m.pressure = s.pressure_pa;
  return m;
}
height_t toLcm(const HeightSample& s) {
  height_t m;
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
  requireWithin(m.variance, 0.0, plausible::kMaxRange_m * plausible::kMaxRange_m, "variance [m^2]");
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
  requireFinite(m.cov_p, "cov_p");
  requireFinite(m.cov_v, "cov_v");
  requireFinite(m.cov_theta, "cov_theta");
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
  requireFinite(m.cov_p, "cov_p");
  AnchorEstimate s;
  s.t = Timestamp::fromUtime(m.utime);
  s.id = m.id;
  s.p_AinG = get3(m.p_AinG);
  s.cov_p_m2 = get33(m.cov_p);
  return s;
}

anchors_t toLcm(Timestamp t, const std::vector<AnchorEstimate>& anchors) {
  anchors_t m;
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

// ------------------------------------------------------------------------------ status, commands

estimator_status_t toLcm(const EstimatorStatus& s) {
  estimator_status_t m;
  m.utime = s.t.us;
  m.wall_utime = s.wall_utime;
  m.initialized = s.initialized;
  m.strategy = s.strategy;
  m.num_instances = clampedCount(s.instances);
  for (int i = 0; i < m.num_instances; ++i) {
    const auto& in = s.instances[i];
    instance_status_t o;
    o.id = in.id;
    o.type = in.type;
    o.num_updates = in.n_updates;
    o.num_rejected = in.n_rejected;
    m.instances.push_back(o);
  }
  m.counters = countersToLcm(s.counters);
  m.num_counters = static_cast<int16_t>(m.counters.size());
  for (const auto& [name, us] : s.mean_step_us) {
    if (m.timings.size() == kMaxArray) break;
    timing_t t;
    t.name = name;
    t.mean_us = us;
    m.timings.push_back(t);
  }
  m.num_timings = static_cast<int16_t>(m.timings.size());
  m.health = s.health;
  m.health_reason = s.health_reason;
  m.sigma_p_max_m = s.sigma_p_max_m;
  for (int i = 0; i < 3; ++i) m.weak_axis_G[i] = s.weak_axis_G[i];
  m.sigma_yaw_deg = s.sigma_yaw_deg;
  return m;
}
EstimatorStatus fromLcm(const estimator_status_t& m) {
  EstimatorStatus s;
  s.t = Timestamp::fromUtime(m.utime);
  s.wall_utime = m.wall_utime;
  s.initialized = m.initialized;
  s.strategy = text(m.strategy, "strategy");
  for (const auto& in : m.instances) {
    InstanceStatus o;
    o.id = in.id;
    o.type = text(in.type, "an instance type");
    o.n_updates = in.num_updates;
    o.n_rejected = in.num_rejected;
    s.instances.push_back(o);
  }
  s.counters = countersFromLcm(m.counters);
  for (const auto& t : m.timings) s.mean_step_us[text(t.name, "a timing name")] = t.mean_us;
  s.health = text(m.health, "health");
  s.health_reason = text(m.health_reason, "health_reason");
  s.sigma_p_max_m = m.sigma_p_max_m;
  s.weak_axis_G = Eigen::Vector3d(m.weak_axis_G[0], m.weak_axis_G[1], m.weak_axis_G[2]);
  s.sigma_yaw_deg = m.sigma_yaw_deg;
  return s;
}

estimator_cmd_t toLcm(const EstimatorCommand& s) {
  estimator_cmd_t m;
  m.utime = s.t.us;
  m.action = static_cast<int8_t>(s.action);
  m.id = s.id;
  m.anchor = toLcm(s.anchor);
  return m;
}
EstimatorCommand fromLcm(const estimator_cmd_t& m) {
  EstimatorCommand s;
  s.t = Timestamp::fromUtime(m.utime);
  switch (m.action) {
    case estimator_cmd_t::ADD_ANCHOR: s.action = EstimatorCommand::Action::AddAnchor; break;
    case estimator_cmd_t::REMOVE_INSTANCE: s.action = EstimatorCommand::Action::RemoveInstance; break;
    case estimator_cmd_t::RESET: s.action = EstimatorCommand::Action::Reset; break;
    default: throw InvalidMessage("unknown estimator command action " + std::to_string(m.action));
  }
  s.id = m.id;
  // The anchor part is decoded by the one anchor_init_t conversion, with its checks. It only matters
  // for AddAnchor: for the other actions an invalid one is dropped rather than rejecting the command.
  if (s.action == EstimatorCommand::Action::AddAnchor) {
    s.anchor = fromLcm(m.anchor);
  } else {
    try {
      s.anchor = fromLcm(m.anchor);
    } catch (const InvalidMessage&) {
      s.anchor = AnchorInit{};
    }
  }
  return s;
}

calib_cmd_t toLcm(const CalibCommand& s) {
  calib_cmd_t m;
  m.utime = s.t.us;
  m.action = static_cast<int8_t>(s.action);
  m.num_anchors = clampedCount(s.anchors);
  m.anchors.assign(s.anchors.begin(), s.anchors.begin() + m.num_anchors);
  return m;
}
CalibCommand fromLcm(const calib_cmd_t& m) {
  CalibCommand s;
  s.t = Timestamp::fromUtime(m.utime);
  switch (m.action) {
    case calib_cmd_t::COLLECT: s.action = CalibCommand::Action::Collect; break;
    case calib_cmd_t::CALIBRATE: s.action = CalibCommand::Action::Calibrate; break;
    case calib_cmd_t::ABORT: s.action = CalibCommand::Action::Abort; break;
    default: throw InvalidMessage("unknown calibration command action " + std::to_string(m.action));
  }
  s.anchors.assign(m.anchors.begin(), m.anchors.end());
  return s;
}

calib_status_t toLcm(const CalibStatus& s) {
  calib_status_t m;
  m.utime = s.t.us;
  m.wall_utime = s.wall_utime;
  m.num_anchors = clampedCount(s.anchors);
  for (int i = 0; i < m.num_anchors; ++i) {
    const auto& a = s.anchors[i];
    calib_anchor_status_t o;
    o.id = a.id;
    o.state = a.state;
    o.num_ranges = a.n_ranges;
    o.num_refs = a.n_refs;
    o.reason = a.reason;
    m.anchors.push_back(o);
  }
  m.counters = countersToLcm(s.counters);
  m.num_counters = static_cast<int16_t>(m.counters.size());
  return m;
}
CalibStatus fromLcm(const calib_status_t& m) {
  CalibStatus s;
  s.t = Timestamp::fromUtime(m.utime);
  s.wall_utime = m.wall_utime;
  for (const auto& a : m.anchors) {
    CalibAnchorStatus o;
    o.id = a.id;
    o.state = text(a.state, "an anchor state");
    o.n_ranges = a.num_ranges;
    o.n_refs = a.num_refs;
    o.reason = text(a.reason, "an anchor reason");
    s.anchors.push_back(o);
  }
  s.counters = countersFromLcm(m.counters);
  return s;
}

mission_status_t toLcm(const MissionStatus& s) {
  mission_status_t m;
  m.utime = s.t.us;
  m.wall_utime = s.wall_utime;
  m.step_index = s.step_index;
  m.num_steps = s.n_steps;
  m.text = s.text;
  return m;
}
MissionStatus fromLcm(const mission_status_t& m) {
  MissionStatus s;
  s.t = Timestamp::fromUtime(m.utime);
  s.wall_utime = m.wall_utime;
  s.step_index = m.step_index;
  s.n_steps = m.num_steps;
  s.text = text(m.text, "text");
  return s;
}

}  // namespace meshnav::transport
