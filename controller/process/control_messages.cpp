#include "controller/process/control_messages.h"

#include <spdlog/fmt/fmt.h>

#include <cmath>

namespace meshnav::controller {

namespace {
bool finite(const double* v, int n) {
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}
bool knownMode(int8_t m) { return m >= 0 && m <= 3; }
}  // namespace

ControlMode modeOf(int8_t mode) { return knownMode(mode) ? static_cast<ControlMode>(mode) : ControlMode::Idle; }

control_cmd_t toLcm(const ControlCommand& c, ControlMode mode) {
  control_cmd_t m{};
  m.utime = c.t.us;
  m.thrust_m_s2 = c.thrust_m_s2;
  for (int i = 0; i < 3; ++i) m.w_IinI[i] = c.w_IinI[i];
  m.mode = static_cast<int8_t>(mode);
  return m;
}

control_status_t toLcm(const ControlStatus& s, int64_t updates, double jitter_p99_ms, double jitter_max_ms) {
  control_status_t m{};
  m.utime = s.t.us;
  m.mode = static_cast<int8_t>(s.mode);
  m.phase = s.phase;
  m.waypoint = s.waypoint;
  m.failsafe_events = s.failsafe_events;
  m.failsafe_reason = s.failsafe_reason;
  m.pose_age_s = s.pose_age_s;
  m.position_cov_trace_m2 = s.position_cov_trace_m2;
  for (int i = 0; i < 3; ++i) {
    m.setpoint_p_IinG[i] = s.setpoint.p_IinG[i];
    m.setpoint_v_IinG[i] = s.setpoint.v_IinG[i];
    m.w_IinI[i] = s.command.w_IinI[i];
  }
  m.setpoint_yaw_rad = s.setpoint.yaw_rad;
  m.thrust_m_s2 = s.command.thrust_m_s2;
  m.mission_complete = s.mission_complete;
  m.updates = updates;
  m.jitter_p99_ms = jitter_p99_ms;
  m.jitter_max_ms = jitter_max_ms;
  return m;
}

std::string invalidReason(const control_cmd_t& m) {
  if (!knownMode(m.mode)) return "unknown mode " + std::to_string(m.mode);
  if (!std::isfinite(m.thrust_m_s2) || !finite(m.w_IinI, 3)) return "thrust or rates not finite";
  if (m.thrust_m_s2 < 0.0) return "negative thrust";
  return "";
}

std::string invalidReason(const control_status_t& m) {
  if (!knownMode(m.mode)) return "unknown mode " + std::to_string(m.mode);
  if (!finite(m.setpoint_p_IinG, 3) || !finite(m.setpoint_v_IinG, 3) || !finite(m.w_IinI, 3) ||
      !std::isfinite(m.thrust_m_s2) || !std::isfinite(m.setpoint_yaw_rad) || !std::isfinite(m.pose_age_s))
    return "a number is not finite";
  return "";
}

std::vector<std::pair<std::string, std::string>> statusFields(const control_status_t& m) {
  const ControlStatus s = fromLcm(m);
  std::string mode = toString(s.mode);
  if (!s.phase.empty()) mode += " / " + s.phase + (s.waypoint >= 0 ? " to waypoint " + std::to_string(s.waypoint + 1) : "");
  if (s.mission_complete) mode += " (mission complete)";
  std::vector<std::pair<std::string, std::string>> f;
  f.emplace_back("mode", mode);
  f.emplace_back("failsafe events", std::to_string(s.failsafe_events) +
                                        (s.failsafe_reason.empty() ? "" : " (last: " + s.failsafe_reason + ")"));
  f.emplace_back("POSE", s.pose_age_s < 0.0 ? std::string("none yet")
                                            : fmt::format("{:.3f} s old, cov trace {:.4f} m²", s.pose_age_s,
                                                          s.position_cov_trace_m2));
  f.emplace_back("setpoint", fmt::format("[{:.2f}, {:.2f}, {:.2f}] m, yaw {:.0f}°", s.setpoint.p_IinG.x(),
                                         s.setpoint.p_IinG.y(), s.setpoint.p_IinG.z(), s.setpoint.yaw_rad * 57.29577951308232));
  f.emplace_back("command", fmt::format("thrust {:.2f} m/s², rates [{:.2f}, {:.2f}, {:.2f}] rad/s", s.command.thrust_m_s2,
                                        s.command.w_IinI.x(), s.command.w_IinI.y(), s.command.w_IinI.z()));
  f.emplace_back("loop", m.jitter_p99_ms < 0.0 ? std::to_string(m.updates) + " updates"
                                               : fmt::format("{} updates, jitter p99 {:.2f} ms, max {:.2f} ms", m.updates,
                                                             m.jitter_p99_ms, m.jitter_max_ms));
  return f;
}

ControlStatus fromLcm(const control_status_t& m) {
  ControlStatus s;
  s.t = Timestamp{m.utime};
  s.mode = modeOf(m.mode);
  s.phase = m.phase;
  s.waypoint = m.waypoint;
  s.failsafe_events = m.failsafe_events;
  s.failsafe_reason = m.failsafe_reason;
  s.pose_age_s = m.pose_age_s;
  s.position_cov_trace_m2 = m.position_cov_trace_m2;
  for (int i = 0; i < 3; ++i) {
    s.setpoint.p_IinG[i] = m.setpoint_p_IinG[i];
    s.setpoint.v_IinG[i] = m.setpoint_v_IinG[i];
    s.command.w_IinI[i] = m.w_IinI[i];
  }
  s.setpoint.yaw_rad = m.setpoint_yaw_rad;
  s.command.t = s.t;
  s.command.thrust_m_s2 = m.thrust_m_s2;
  s.mission_complete = m.mission_complete;
  return s;
}

}  // namespace meshnav::controller
