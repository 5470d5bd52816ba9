#pragma once
/// @file clock_offset.h
/// @brief Offset of a local clock against a reference clock from request/reply exchanges
/// (TIME_SYNC, docs/deployment.md "Time across hosts"), free of LCM.
///
/// One exchange: the client sends at t1 (its clock), the reference receives at t2 and replies at
/// t3 (reference clock), the client receives the reply at t4 (its clock). With one-way delays
/// d_up, d_down and θ = reference − client:
///
///   t2 = t1 + θ + d_up,   t4 = t3 − θ + d_down
///   θ̂ = ((t2 − t1) + (t3 − t4)) / 2 = θ + (d_up − d_down) / 2
///   δ = (t4 − t1) − (t3 − t2) = d_up + d_down        (round-trip delay)
///
/// so |θ̂ − θ| ≤ δ / 2 whatever the delays. The estimate is θ̂ of the exchange with the smallest δ
/// among the last `window` accepted ones (the one least disturbed by queueing and jitter, as NTP's
/// clock filter does). An exchange with negative δ or a reply older than its request is refused and
/// counted ("time_sync:bad_exchange"); a δ above `max_delay_us` is counted
/// ("time_sync:slow_exchange") and not used.

#include <cstdint>
#include <deque>
#include <optional>

#include "common/diagnostics.h"

namespace meshnav {

/// One request/reply exchange [µs]: t1, t4 on the client's clock, t2, t3 on the reference clock.
struct ClockExchange {
  int64_t t1 = 0, t2 = 0, t3 = 0, t4 = 0;
  /// θ̂ = ((t2 − t1) + (t3 − t4)) / 2 [µs] (reference − client).
  int64_t offset() const;
  /// δ = (t4 − t1) − (t3 − t2) [µs].
  int64_t roundTrip() const;
};

struct ClockOffsetOptions {
  int window = 16;                   ///< exchanges kept; the smallest round trip among them wins [-]
  int64_t max_delay_us = 1'000'000;  ///< exchanges with a longer round trip are not used [µs]
};

class ClockOffsetEstimator {
 public:
  /// Throws std::invalid_argument for window < 1 or max_delay_us <= 0.
  explicit ClockOffsetEstimator(ClockOffsetOptions options = {});
  /// Adds one exchange; false when it was refused (counted in `diag`).
  bool add(const ClockExchange& e, Diagnostics& diag);
  /// θ̂ [µs] (reference − client): add it to a client time to get reference time. nullopt before
  /// the first accepted exchange.
  std::optional<int64_t> offset() const;
  /// Bound of |θ̂ − θ| [µs]: half the round trip of the exchange used.
  std::optional<int64_t> errorBound() const;
  int64_t accepted() const { return accepted_; }

 private:
  const ClockExchange* best() const;
  ClockOffsetOptions options_;
  std::deque<ClockExchange> kept_;
  int64_t accepted_ = 0;
};

}  // namespace meshnav
