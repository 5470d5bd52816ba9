#pragma once
/// @file convert.h
/// @brief Conversions between the plain structs of common/types.h, common/messages.h and the LCM
/// messages of lcmtypes/ (both ways, field by field, lossless: fromLcm(toLcm(x)) == x).
///
/// Conventions on the wire: quaternions [w, x, y, z] (Hamilton), 3×3 matrices row-major
/// (element (r, c) at index 3r + c), time `utime` [µs] = Timestamp::us, maps (counters, timings)
/// as arrays sorted by name.
///
/// `fromLcm` of a *measurement* (IMU, BARO, RANGE, PEER_RANGE, FLIGHT_STATE, GROUND_TRUTH, ANCHOR_INIT,
/// commands) validates what the decoder cannot: non-finite numbers and unknown enumeration codes
/// throw `InvalidMessage`, which the process runtime reports and counts per channel.

#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "common/messages.h"
#include "common/types.h"
#include "meshnav/anchor_estimate_t.hpp"
#include "meshnav/anchor_init_t.hpp"
#include "meshnav/anchors_t.hpp"
#include "meshnav/baro_t.hpp"
#include "meshnav/height_t.hpp"
#include "meshnav/calib_cmd_t.hpp"
#include "meshnav/calib_status_t.hpp"
#include "meshnav/estimator_cmd_t.hpp"
#include "meshnav/estimator_status_t.hpp"
#include "meshnav/flight_state_t.hpp"
#include "meshnav/ground_truth_t.hpp"
#include "meshnav/imu_t.hpp"
#include "meshnav/mission_status_t.hpp"
#include "meshnav/pair_bias_t.hpp"
#include "meshnav/peer_range_t.hpp"
#include "meshnav/pose_t.hpp"
#include "meshnav/range_t.hpp"

namespace meshnav::transport {

/// A decoded message whose content is invalid (NaN, unknown enumeration code, ...).
class InvalidMessage : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

imu_t toLcm(const ImuSample& s);
baro_t toLcm(const BaroSample& s);
height_t toLcm(const HeightSample& s);
range_t toLcm(const RangeSample& s);
flight_state_t toLcm(const FlightStateSample& s);
ground_truth_t toLcm(const PoseSample& s);
pose_t toLcm(const PoseEstimate& s);
peer_range_t toLcm(const PeerRange& s);
anchor_estimate_t toLcm(const AnchorEstimate& s);
pair_bias_t toLcm(const PairBias& s);
anchor_init_t toLcm(const AnchorInit& s);
estimator_status_t toLcm(const EstimatorStatus& s);
estimator_cmd_t toLcm(const EstimatorCommand& s);
calib_cmd_t toLcm(const CalibCommand& s);
calib_status_t toLcm(const CalibStatus& s);
mission_status_t toLcm(const MissionStatus& s);
/// ANCHORS: every anchor estimate at filter time `t`.
anchors_t toLcm(Timestamp t, const std::vector<AnchorEstimate>& anchors);
/// ANCHORS stamped with the newest anchor time (0 when empty).
anchors_t toLcm(const std::vector<AnchorEstimate>& anchors);

ImuSample fromLcm(const imu_t& m);
BaroSample fromLcm(const baro_t& m);
HeightSample fromLcm(const height_t& m);
RangeSample fromLcm(const range_t& m);
FlightStateSample fromLcm(const flight_state_t& m);
PoseSample fromLcm(const ground_truth_t& m);
PoseEstimate fromLcm(const pose_t& m);
/// Also refuses a utime other than range.utime and a peer_tag that is no end of the range.
PeerRange fromLcm(const peer_range_t& m);
AnchorEstimate fromLcm(const anchor_estimate_t& m);
PairBias fromLcm(const pair_bias_t& m);
AnchorInit fromLcm(const anchor_init_t& m);
EstimatorStatus fromLcm(const estimator_status_t& m);
EstimatorCommand fromLcm(const estimator_cmd_t& m);
CalibCommand fromLcm(const calib_cmd_t& m);
CalibStatus fromLcm(const calib_status_t& m);
MissionStatus fromLcm(const mission_status_t& m);
std::vector<AnchorEstimate> fromLcm(const anchors_t& m);

/// Plain struct → LCM type, for the typed publish/subscribe of LcmNode.
template <class Plain>
struct LcmTypeOf;
template <> struct LcmTypeOf<ImuSample> { using type = imu_t; };
template <> struct LcmTypeOf<BaroSample> { using type = baro_t; };
template <> struct LcmTypeOf<HeightSample> { using type = height_t; };
template <> struct LcmTypeOf<RangeSample> { using type = range_t; };
template <> struct LcmTypeOf<FlightStateSample> { using type = flight_state_t; };
template <> struct LcmTypeOf<PoseSample> { using type = ground_truth_t; };
template <> struct LcmTypeOf<PoseEstimate> { using type = pose_t; };
template <> struct LcmTypeOf<PeerRange> { using type = peer_range_t; };
template <> struct LcmTypeOf<AnchorInit> { using type = anchor_init_t; };
template <> struct LcmTypeOf<EstimatorStatus> { using type = estimator_status_t; };
template <> struct LcmTypeOf<EstimatorCommand> { using type = estimator_cmd_t; };
template <> struct LcmTypeOf<CalibCommand> { using type = calib_cmd_t; };
template <> struct LcmTypeOf<CalibStatus> { using type = calib_status_t; };
template <> struct LcmTypeOf<MissionStatus> { using type = mission_status_t; };
template <> struct LcmTypeOf<std::vector<AnchorEstimate>> { using type = anchors_t; };

/// What a channel of `T` carries on the wire (channels::Channel<T>): LcmTypeOf<T> for a plain
/// struct, `T` itself for an LCM type that has no plain struct (time_sync_t).
template <class T>
struct WireTypeOf {
  using type = T;
};
template <class T>
  requires requires { typename LcmTypeOf<T>::type; }
struct WireTypeOf<T> {
  using type = typename LcmTypeOf<T>::type;
};
template <class T>
using WireType = typename WireTypeOf<T>::type;

/// `value` as its wire message (toLcm, or itself for an LCM type).
template <class T>
WireType<T> toWire(const T& value) {
  if constexpr (std::is_same_v<WireType<T>, T>)
    return value;
  else
    return toLcm(value);
}
/// A decoded wire message as `T` (fromLcm, which validates, or itself for an LCM type).
template <class T>
T fromWire(const WireType<T>& msg) {
  if constexpr (std::is_same_v<WireType<T>, T>)
    return msg;
  else
    return fromLcm(msg);
}

}  // namespace meshnav::transport
