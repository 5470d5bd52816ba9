#pragma once
/// @file estimator_input.h
/// @brief Everything the estimator node consumes, as one variant, and the canonical processing
/// order: by time, then by kind (flight state, IMU, baro, range, anchor init, command, height),
/// then by ids (height last so that the order among the older kinds stays as it was). Out-of-sequence handling re-processes in exactly this order, so the result does not depend
/// on arrival order.

#include <cstdint>
#include <iterator>
#include <optional>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "common/dataset.h"
#include "common/messages.h"
#include "common/types.h"

namespace meshnav::estimator {

using EstimatorInput =
    std::variant<FlightStateSample, ImuSample, BaroSample, RangeSample, AnchorInit, EstimatorCommand, HeightSample,
                 PeerRange>;

/// Ids of an input that order it among inputs of its kind at equal time (0: none).
struct InputIds {
  SensorId a = 0;
  SensorId b = 0;
};

/// THE table of input kinds, one entry per alternative of EstimatorInput: its rank in the canonical
/// order at equal time (`rank`), its channel name (`name`; counter prefix "RANGE:duplicate",
/// "IMU:time_ahead"; the estimator process subscribes the channel constant of that name and type,
/// transport/channels.h), and optionally `kDataset` (the Dataset member mergeInTimeOrder takes it
/// from), `ids` (InputIds of a sample) and `kDatasetOnly` (no channel: not subscribed by the
/// process, which the channels test checks otherwise). An explicit table, not the variant's index: adding or
/// moving an alternative of EstimatorInput changes no order (test_estimator_input.cpp).
template <class T>
struct InputKind;
template <> struct InputKind<FlightStateSample> { static constexpr int rank = 0; static constexpr const char* name = "FLIGHT_STATE"; static constexpr auto kDataset = &Dataset::flight_states; };
template <> struct InputKind<ImuSample> { static constexpr int rank = 1; static constexpr const char* name = "IMU"; static constexpr auto kDataset = &Dataset::imu; };
template <> struct InputKind<BaroSample> { static constexpr int rank = 2; static constexpr const char* name = "BARO"; static constexpr auto kDataset = &Dataset::baro; };
template <> struct InputKind<RangeSample> {
  static constexpr int rank = 3; static constexpr const char* name = "RANGE"; static constexpr auto kDataset = &Dataset::ranges;
  static InputIds ids(const RangeSample& r) { return {r.id_initiator, r.id_responder}; }
};
template <> struct InputKind<AnchorInit> {
  static constexpr int rank = 4; static constexpr const char* name = "ANCHOR_INIT";
  static InputIds ids(const AnchorInit& a) { return {a.id, 0}; }
};
template <> struct InputKind<EstimatorCommand> {
  static constexpr int rank = 5; static constexpr const char* name = "ESTIMATOR_CMD";
  static InputIds ids(const EstimatorCommand& c) { return {c.id, 0}; }
};
template <> struct InputKind<HeightSample> { static constexpr int rank = 6; static constexpr const char* name = "HEIGHT"; static constexpr auto kDataset = &Dataset::heights; };
/// A fleet's inter-vehicle range with the peer's tag position (pipeline/peer_range_feed.h composes
/// it from the peer's pose: in one process, or over LCM in `peer_router` on PEER_RANGE).
template <> struct InputKind<PeerRange> {
  // First at equal time: the receiver's own IMU sample of that instant comes after it (the fleet's
  // other vehicle is earlier in the merged order), and a later rank would rewind for every range.
  static constexpr int rank = -1; static constexpr const char* name = "PEER_RANGE";
  static InputIds ids(const PeerRange& r) { return {r.range.id_initiator, r.range.id_responder}; }
};

/// Calls `f.template operator()<T>()` for every input kind T, in the variant's order.
template <class F>
void forEachInputKind(F&& f) {
  [&]<size_t... I>(std::index_sequence<I...>) {
    (f.template operator()<std::variant_alternative_t<I, EstimatorInput>>(), ...);
  }(std::make_index_sequence<std::variant_size_v<EstimatorInput>>{});
}

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
  std::visit(
      [&](const auto& m) {
        using K = InputKind<std::decay_t<decltype(m)>>;
        if constexpr (requires { K::ids(m); }) {
          const InputIds ids = K::ids(m);
          o.a = ids.a;
          o.b = ids.b;
        }
      },
      in);
  return o;
}

/// A measurement (range, baro, height): propagated to its own time, which may fall between two IMU
/// samples (EstimatorNode holds it until the sample after it has come).
inline bool isMeasurement(const EstimatorInput& in) {
  return std::holds_alternative<RangeSample>(in) || std::holds_alternative<BaroSample>(in) ||
         std::holds_alternative<HeightSample>(in) || std::holds_alternative<PeerRange>(in);
}

/// The IMU sample after input `i` of a sequence in the canonical order (`at(j)` the j-th input,
/// `n` inputs) when input `i` is a measurement and that sample comes at most `max_dt_s` after it;
/// nullopt otherwise. It is what a measurement between two samples is propagated on
/// (ImuPropagation::toTime), found the same way in every replay of a stored sequence as when the
/// node held the measurement until that sample came.
template <class At>
std::optional<ImuSample> nextImuSample(size_t i, size_t n, At&& at, double max_dt_s) {
  const EstimatorInput& in = at(i);
  if (!isMeasurement(in)) return std::nullopt;
  const Timestamp until = inputTime(in) + Duration::fromSec(max_dt_s);
  for (size_t j = i + 1; j < n; ++j) {
    const EstimatorInput& next = at(j);
    if (inputTime(next) > until) break;
    if (const auto* s = std::get_if<ImuSample>(&next)) return *s;
  }
  return std::nullopt;
}

/// All samples of a dataset (every input kind with a `kDataset`) merged into the canonical order
/// (stable for equal keys: within one time, kind and ids, in the dataset's order).
std::vector<EstimatorInput> mergeInTimeOrder(const Dataset& ds);

}  // namespace meshnav::estimator
