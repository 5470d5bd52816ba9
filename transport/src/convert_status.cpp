/// @file convert_status.cpp
/// @brief Plain struct <-> LCM conversions of the status and command messages (estimator, calibrator,
/// mission): counters, texts refused with a NUL inside. The measurements, estimates and calibration
/// are in convert.cpp.

#include <map>
#include <string>
#include <vector>

#include "transport/convert.h"
#include "transport/src/convert_internals.h"

namespace meshnav::transport {
namespace {

using convert_internal::clampedCount;
using convert_internal::kMaxArray;

/// A string field as received. LCM's encoder writes a string up to its first NUL but sizes the
/// message by the whole string, so a string holding a NUL would not convert back (the message
/// published would end in garbage): refused.
const std::string& text(const std::string& s, const char* what) {
  if (s.find('\0') != std::string::npos) throw InvalidMessage(std::string("NUL byte inside the text of ") + what);
  return s;
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

// ------------------------------------------------------------------------------ status, commands

estimator_status_t toLcm(const EstimatorStatus& s) {
  estimator_status_t m;
  m.sender_id = 0;  // set by LcmNode::publish
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
  m.uwb_clock_offset_s = s.uwb_clock_offset_s;
  m.uwb_clock_offset_sigma_s = s.uwb_clock_offset_sigma_s;
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
  s.uwb_clock_offset_s = m.uwb_clock_offset_s;
  s.uwb_clock_offset_sigma_s = m.uwb_clock_offset_sigma_s;
  return s;
}

estimator_cmd_t toLcm(const EstimatorCommand& s) {
  estimator_cmd_t m;
  m.sender_id = 0;  // set by LcmNode::publish
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
  m.sender_id = 0;  // set by LcmNode::publish
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
  m.sender_id = 0;  // set by LcmNode::publish
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
  m.sender_id = 0;  // set by LcmNode::publish
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
