#pragma once
/// @file channels.h
/// @brief LCM channels (docs/channels.md): each a name (UPPER_SNAKE) and the message it carries.
/// Every process uses these constants; a launch file may remap nothing, so the names are the
/// contract between processes.
///
/// A channel's type is part of the constant, `Channel<Msg>`, and LcmNode's typed publish and
/// subscribe take the constant: `node.subscribe(channels::kBaro, [](const ImuSample&) {...})`
/// or `node.publish(channels::kImu, BaroSample{})` does not compile
/// (tests/unit/transport/test_channels.cpp). `Msg` is the plain struct of common/ when the
/// message has one (converted by transport/convert.h), else the LCM type itself (time_sync_t).
/// A plain string is left only where a name is really dynamic: the logger's raw regex, and the
/// mission's --time-channels, which it matches against these constants.
///
/// Fleets (docs/channels.md, "Vehicle prefixes"): each vehicle's channels carry its prefix on the
/// wire, `v0/POSE`, `UAV1/IMU`; the few the fleet shares (kFleetShared: the one calibrator's and
/// the one mission's) do not. `prefixed(channel, prefix)` is the only place that makes such a
/// name; LcmNode applies it to every typed publish and subscribe of a process started with
/// `--channel-prefix P` (transport/process_main.h).

#include <array>
#include <stdexcept>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <vector>

#include "common/fleet_file.h"
#include "common/messages.h"
#include "common/types.h"
#include "meshnav/control_cmd_t.hpp"
#include "meshnav/control_status_t.hpp"
#include "meshnav/time_sync_t.hpp"

namespace meshnav::channels {

/// A channel name with the type of its messages.
template <class Msg>
struct Channel {
  using Message = Msg;
  const char* name;
};

inline constexpr Channel<ImuSample> kImu{"IMU"};                              ///< imu_t, imu_bridge → estimator
inline constexpr Channel<BaroSample> kBaro{"BARO"};                           ///< baro_t
inline constexpr Channel<RangeSample> kRange{"RANGE"};                        ///< range_t, uwb_bridge → estimator, calibrator
/// peer_range_t, peer_router → estimator: a range to another vehicle's tag with where that vehicle puts it
inline constexpr Channel<PeerRange> kPeerRange{"PEER_RANGE"};
inline constexpr Channel<FlightStateSample> kFlightState{"FLIGHT_STATE"};     ///< flight_state_t
inline constexpr Channel<HeightSample> kHeight{"HEIGHT"};                     ///< height_t, imu_bridge → estimator
inline constexpr Channel<PoseSample> kGroundTruth{"GROUND_TRUTH"};            ///< ground_truth_t (simulator, logs)
inline constexpr Channel<AnchorInit> kAnchorInit{"ANCHOR_INIT"};              ///< anchor_init_t, calibrator → estimator
inline constexpr Channel<PoseEstimate> kPose{"POSE"};                         ///< pose_t, estimator →
/// pose_t, estimator → (fixed-lag smoothed, `fixed_lag.lag_s` or more after its utime; docs/smoother.md)
inline constexpr Channel<PoseEstimate> kPoseSmoothed{"POSE_SMOOTHED"};
inline constexpr Channel<std::vector<AnchorEstimate>> kAnchors{"ANCHORS"};    ///< anchors_t, estimator →
inline constexpr Channel<EstimatorStatus> kEstimatorStatus{"ESTIMATOR_STATUS"}; ///< estimator_status_t (heartbeat)
inline constexpr Channel<EstimatorCommand> kEstimatorCmd{"ESTIMATOR_CMD"};    ///< estimator_cmd_t, mission → estimator
inline constexpr Channel<CalibCommand> kCalibCmd{"CALIB_CMD"};                ///< calib_cmd_t, mission → calibrator
inline constexpr Channel<CalibStatus> kCalibStatus{"CALIB_STATUS"};           ///< calib_status_t (heartbeat)
inline constexpr Channel<MissionStatus> kMissionStatus{"MISSION_STATUS"};     ///< mission_status_t (heartbeat)
inline constexpr Channel<time_sync_t> kTimeSyncRequest{"TIME_SYNC_REQUEST"};  ///< time_sync_t, bridges → estimator (clock reference)
inline constexpr Channel<time_sync_t> kTimeSync{"TIME_SYNC"};                 ///< time_sync_t, estimator → bridges (replies)
/// control_cmd_t, controller → vehicle_sim: thrust and body rates answering the IMU sample of its utime
inline constexpr Channel<control_cmd_t> kControlCmd{"CONTROL_CMD"};
/// control_status_t, controller → logging, view, vehicle_sim (mode, failsafe, setpoint, loop jitter)
inline constexpr Channel<control_status_t> kControlStatus{"CONTROL_STATUS"};

/// Every channel constant above, once: the list kAll and `find` are made from.
inline constexpr auto kTyped =
    std::tuple{kImu,  kBaro,           kRange,     kFlightState, kGroundTruth,   kAnchorInit,      kPose,     kAnchors,
               kEstimatorStatus, kEstimatorCmd, kCalibCmd, kCalibStatus, kMissionStatus, kHeight, kTimeSyncRequest,
               kTimeSync,        kPoseSmoothed,    kControlCmd,   kControlStatus, kPeerRange};

/// The name of every channel above, for tools that list or record them.
inline constexpr auto kAll =
    std::apply([](const auto&... c) { return std::array<const char*, sizeof...(c)>{c.name...}; }, kTyped);

/// Channels that several processes publish by design: RANGE (one uwb_bridge per anchor on a
/// multi-host launch), the commands (mission, an operator's tool) and the time-sync requests
/// (every bridge on another host). Every other channel has one publisher, whose instance id
/// (`sender_id`) transport/publisher_watch.h holds each receiver to.
inline constexpr std::array<const char*, 4> kSeveralPublishers{"RANGE", "ESTIMATOR_CMD", "CALIB_CMD",
                                                              "TIME_SYNC_REQUEST"};

/// True for a channel of the list above that has one publisher (false for a name not there).
constexpr bool hasOnePublisher(std::string_view name) {
  for (const char* s : kSeveralPublishers)
    if (name == s) return false;
  for (const char* c : kAll)
    if (name == c) return true;
  return false;
}

/// Channels a fleet shares on one LCM network, never prefixed: the fleet's one calibrator takes
/// commands and reports on them for every vehicle, the one mission reports on MISSION_STATUS.
/// Every other channel belongs to one vehicle (its sensors, its estimator, its ANCHOR_INIT, which
/// the calibrator addresses to it alone, as pipeline/fleet.h's restrictToVehicle does in one
/// process).
inline constexpr std::array<const char*, 3> kFleetShared{"CALIB_CMD", "CALIB_STATUS", "MISSION_STATUS"};

/// True for a channel of kFleetShared.
constexpr bool isFleetShared(std::string_view name) {
  for (const char* s : kFleetShared)
    if (name == s) return true;
  return false;
}

/// Empty when `prefix` can prefix a vehicle's channels (a fleet file's vehicle name: 1-64 of
/// [A-Za-z0-9_-]), else why not, e.g. "'a/b' must be 1-64 letters, digits, '_' or '-'".
inline std::string prefixProblem(std::string_view prefix) {
  if (isVehicleName(prefix)) return "";
  return "'" + std::string(prefix) + "' must be 1-64 letters, digits, '_' or '-' (a vehicle name of the fleet file)";
}

/// The name on the wire of the channel named `name` for the vehicle `prefix`: "PREFIX/NAME", or
/// NAME itself for a shared channel (kFleetShared) or an empty prefix (one vehicle, no fleet).
/// Throws std::invalid_argument for a prefix that prefixProblem refuses.
inline std::string prefixedName(std::string_view name, std::string_view prefix) {
  if (prefix.empty() || isFleetShared(name)) return std::string(name);
  if (const std::string why = prefixProblem(prefix); !why.empty())
    throw std::invalid_argument("channel prefix " + why);
  return std::string(prefix) + "/" + std::string(name);
}

/// prefixedName of a typed channel: `prefixed(kPose, "v0")` is "v0/POSE".
template <class Msg>
std::string prefixed(Channel<Msg> channel, std::string_view prefix) {
  return prefixedName(channel.name, prefix);
}

/// The channel name without its vehicle prefix: "v0/POSE" -> "POSE", "POSE" -> "POSE".
constexpr std::string_view unprefixedName(std::string_view wire) {
  const size_t slash = wire.rfind('/');
  return slash == std::string_view::npos ? wire : wire.substr(slash + 1);
}

/// The channel constant of message type `Msg` named `name`, found at compile time (a Channel with
/// a null name when there is none): the estimator process subscribes every input kind of
/// estimator/node/estimator_input.h through it, from the kind's type and channel name.
template <class Msg>
consteval Channel<Msg> find(std::string_view name) {
  Channel<Msg> found{nullptr};
  std::apply(
      [&](const auto&... c) {
        (
            [&] {
              if constexpr (std::is_same_v<std::decay_t<decltype(c)>, Channel<Msg>>)
                if (std::string_view(c.name) == name) found = c;
            }(),
            ...);
      },
      kTyped);
  return found;
}

}  // namespace meshnav::channels
