#pragma once
/// @file control_messages.h
/// @brief CONTROL_CMD and CONTROL_STATUS (lcmtypes/types/control_cmd_t.lcm, control_status_t.lcm)
/// to and from the controller library's structs (controller/setpoint.h, controller_node.h). The
/// channels carry the LCM types themselves (transport/channels.h); the controller library stays
/// free of LCM, so its conversions live here, beside the process.

#include <string>
#include <utility>
#include <vector>

#include "controller/controller_node.h"
#include "controller/setpoint.h"
#include "meshnav/control_cmd_t.hpp"
#include "meshnav/control_status_t.hpp"

namespace meshnav::controller {

control_cmd_t toLcm(const ControlCommand& c, ControlMode mode);
/// `jitter_p99_ms` / `jitter_max_ms`: the process's loop jitter (−1: not measured), `updates`:
/// controller updates so far.
control_status_t toLcm(const ControlStatus& s, int64_t updates, double jitter_p99_ms, double jitter_max_ms);

/// Empty when `m` is usable (finite numbers, a known mode), else why not: the receiver counts and
/// drops it ("CONTROL_CMD:invalid_message").
std::string invalidReason(const control_cmd_t& m);
std::string invalidReason(const control_status_t& m);

/// CONTROL_STATUS as the name/value lines of a status row (the live view, view/view_state.h
/// onStatusFields): mode (with phase and leg), failsafe events and reason, POSE age and covariance,
/// setpoint, command, loop jitter.
std::vector<std::pair<std::string, std::string>> statusFields(const control_status_t& m);

/// CONTROL_STATUS back to the library's struct (the evaluation of vehicle_sim, the view).
ControlStatus fromLcm(const control_status_t& m);
/// The mode of a message (a value out of range: Idle; check invalidReason first).
ControlMode modeOf(int8_t mode);

}  // namespace meshnav::controller
