#pragma once
/// @file clock.h
/// @brief Wall clock behind an interface, so that pacing logic is tested with a fake clock and no
/// test ever sleeps.

#include <cstdint>

namespace meshnav::replay {

/// Source of wall time [µs since the Unix epoch] and a way to wait for it.
class Clock {
 public:
  virtual ~Clock() = default;
  /// Current wall time [µs since the Unix epoch].
  virtual int64_t nowUtime() = 0;
  /// Blocks until `wall_utime` or at most `max_wait_us` (whichever is first); a fake clock advances
  /// its time instead. Callers loop, so a short wait is always correct.
  virtual void sleepUntil(int64_t wall_utime, int64_t max_wait_us) = 0;
};

/// The real clock: CLOCK_REALTIME, sleeping with std::this_thread::sleep_for.
class SystemClock final : public Clock {
 public:
  int64_t nowUtime() override;
  void sleepUntil(int64_t wall_utime, int64_t max_wait_us) override;
};

/// Current wall time [µs since the Unix epoch] (CLOCK_REALTIME).
int64_t wallUtimeNow();
/// A monotonic time [µs] from an arbitrary origin (std::chrono::steady_clock): for intervals
/// (pacing, loop jitter), which a wall clock step would falsify.
int64_t monotonicUsNow();

}  // namespace meshnav::replay
