#include "common/clock_offset.h"

#include <stdexcept>
#include <string>

namespace meshnav {

int64_t ClockExchange::offset() const { return ((t2 - t1) + (t3 - t4)) / 2; }

int64_t ClockExchange::roundTrip() const { return (t4 - t1) - (t3 - t2); }

ClockOffsetEstimator::ClockOffsetEstimator(ClockOffsetOptions options) : options_(options) {
  if (options_.window < 1) throw std::invalid_argument("clock offset: window must be >= 1");
  if (options_.max_delay_us <= 0) throw std::invalid_argument("clock offset: max_delay_us must be > 0");
}

bool ClockOffsetEstimator::add(const ClockExchange& e, Diagnostics& diag) {
  // Stamps are µs since the epoch (now about 1.8e15): anything beyond ±1e17 µs (3000 years) is
  // not a clock reading, and differences of readings within it cannot overflow.
  constexpr int64_t kLimit = 100'000'000'000'000'000;
  for (int64_t v : {e.t1, e.t2, e.t3, e.t4})
    if (v < -kLimit || v > kLimit) {
      diag.report("time_sync:bad_exchange", "time sync: a stamp beyond ±1e17 µs (" + std::to_string(v) + ")");
      return false;
    }
  if (e.t4 < e.t1 || e.t3 < e.t2 || e.roundTrip() < 0) {
    diag.report("time_sync:bad_exchange", "time sync: inconsistent exchange t1=" + std::to_string(e.t1) +
                                              " t2=" + std::to_string(e.t2) + " t3=" + std::to_string(e.t3) +
                                              " t4=" + std::to_string(e.t4) + " µs");
    return false;
  }
  if (e.roundTrip() > options_.max_delay_us) {
    diag.count("time_sync:slow_exchange");
    return false;
  }
  kept_.push_back(e);
  while (static_cast<int>(kept_.size()) > options_.window) kept_.pop_front();
  ++accepted_;
  return true;
}

const ClockExchange* ClockOffsetEstimator::best() const {
  const ClockExchange* b = nullptr;
  for (const auto& e : kept_)
    if (!b || e.roundTrip() < b->roundTrip()) b = &e;
  return b;
}

std::optional<int64_t> ClockOffsetEstimator::offset() const {
  const auto* b = best();
  return b ? std::optional<int64_t>(b->offset()) : std::nullopt;
}

std::optional<int64_t> ClockOffsetEstimator::errorBound() const {
  const auto* b = best();
  return b ? std::optional<int64_t>(b->roundTrip() / 2) : std::nullopt;
}

}  // namespace meshnav
