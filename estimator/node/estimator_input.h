#pragma once
/// @file estimator_input.h
/// @brief Everything the estimator node consumes, as one variant, and the canonical processing
/// order: by time, then by kind (flight state, IMU, baro, range, anchor init, command, height),
/// then by ids (height last so that the order among the older kinds stays as it was). Out-of-sequence handling re-processes in exactly this order, so the result does not depend
/// on arrival order.

#include <cstdint>
#include <iterator>
#include <tuple>
#include <type_traits>
#include <variant>
#include <vector>

#include "common/dataset.h"
#include "common/messages.h"
#include "common/types.h"

namespace meshnav::estimator {

using EstimatorInput =
    std::variant<FlightStateSample, ImuSample, BaroSample, RangeSample, AnchorInit, EstimatorCommand, HeightSample>;

/// The canonical order of the kinds at equal time (`rank`) and each kind's channel name (counter
/// prefix: "RANGE:duplicate", "IMU:time_ahead"). An explicit table, not the variant's index: adding
/// or moving an alternative of EstimatorInput changes no order (test_estimator_input.cpp).
template <class T>
struct InputKind;
template <> struct InputKind<FlightStateSample> { static constexpr int rank = 0; static constexpr const char* name = "FLIGHT_STATE"; };
template <> struct InputKind<ImuSample> { static constexpr int rank = 1; static constexpr const char* name = "IMU"; };
template <> struct InputKind<BaroSample> { static constexpr int rank = 2; static constexpr const char* name = "BARO"; };
template <> struct InputKind<RangeSample> { static constexpr int rank = 3; static constexpr const char* name = "RANGE"; };
template <> struct InputKind<AnchorInit> { static constexpr int rank = 4; static constexpr const char* name = "ANCHOR_INIT"; };
template <> struct InputKind<EstimatorCommand> { static constexpr int rank = 5; static constexpr const char* name = "ESTIMATOR_CMD"; };
template <> struct InputKind<HeightSample> { static constexpr int rank = 6; static constexpr const char* name = "HEIGHT"; };

/// Sort key of an input (time, kind = InputKind rank, ids).
struct InputOrder {
  int64_t t_us = 0;
  int kind = 0;
  SensorId a = 0;
  SensorId b = 0;
  auto operator<=>(const InputOrder&) const = default;
};

inline Timestamp inputTime(const EstimatorInput& in) {
  return std::visit([](const auto& m) { return m.t; }, in);
}

/// Kind of an input as its channel name (InputKind::name).
inline const char* inputKindName(const EstimatorInput& in) {
  return std::visit([](const auto& m) { return InputKind<std::decay_t<decltype(m)>>::name; }, in);
}

/// Rank of an input's kind in the canonical order (InputKind::rank).
inline int inputKindRank(const EstimatorInput& in) {
  return std::visit([](const auto& m) { return InputKind<std::decay_t<decltype(m)>>::rank; }, in);
}

inline InputOrder inputOrder(const EstimatorInput& in) {
  InputOrder o;
  o.t_us = inputTime(in).us;
  o.kind = inputKindRank(in);
  if (const auto* r = std::get_if<RangeSample>(&in)) {
    o.a = r->id_initiator;
    o.b = r->id_responder;
  } else if (const auto* a = std::get_if<AnchorInit>(&in)) {
    o.a = a->id;
  } else if (const auto* c = std::get_if<EstimatorCommand>(&in)) {
    o.a = c->id;
  }
  return o;
}

/// All samples of a dataset merged into the canonical order (stable for equal keys).
std::vector<EstimatorInput> mergeInTimeOrder(const Dataset& ds);

}  // namespace meshnav::estimator
