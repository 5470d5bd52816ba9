#pragma once
/// @file estimator_input.h
/// @brief Everything the estimator node consumes, as one variant, and the canonical processing
/// order: by time, then by kind (flight state, IMU, baro, range, anchor init, command, height),
/// then by ids (height last so that the order among the older kinds stays as it was). Out-of-sequence handling re-processes in exactly this order, so the result does not depend
/// on arrival order.

#include <cstdint>
#include <iterator>
#include <tuple>
#include <variant>
#include <vector>

#include "common/dataset.h"
#include "common/messages.h"
#include "common/types.h"

namespace meshnav::estimator {

using EstimatorInput =
    std::variant<FlightStateSample, ImuSample, BaroSample, RangeSample, AnchorInit, EstimatorCommand, HeightSample>;

/// Sort key of an input (time, kind = variant index, ids).
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

/// Kind of an input as its channel name (counter prefix: "RANGE:duplicate", "IMU:time_ahead").
inline const char* inputKindName(const EstimatorInput& in) {
  static const char* const kNames[] = {"FLIGHT_STATE", "IMU", "BARO", "RANGE", "ANCHOR_INIT", "ESTIMATOR_CMD", "HEIGHT"};
  static_assert(std::variant_size_v<EstimatorInput> == std::size(kNames));
  return kNames[in.index()];
}

inline InputOrder inputOrder(const EstimatorInput& in) {
  InputOrder o;
  o.t_us = inputTime(in).us;
  o.kind = static_cast<int>(in.index());
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
