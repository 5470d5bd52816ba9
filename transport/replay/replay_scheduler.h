#pragma once
/// @file replay_scheduler.h
/// @brief Wall-clock pacing of a recorded time line: 1× real time, N× faster, or as fast as
/// possible, with a progress line. Two processes replaying with the same `t0_wall_utime` and
/// `data_t0` emit the same data time at the same wall time, so two bridges stay in step.
///
/// Pacing: an event of data time t is due at wall time
///   w(t) = t0_wall + (t − t0_data) / rate        (rate > 0),
/// and at once when rate = 0. Events already due are emitted back to back (catching up); the
/// scheduler never reorders events.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/time.h"
#include "transport/replay/clock.h"
#include "transport/replay/replay_event.h"

namespace meshnav::replay {

struct ReplayOptions {
  double rate = 1.0;                     ///< playback speed: 1 = real time, N = N× faster, 0 = as fast as possible
  std::optional<int64_t> t0_wall_utime;  ///< wall time [µs, Unix epoch] at which `data_t0` is played (default: at start)
  std::optional<Timestamp> data_t0;      ///< data time played at t0_wall (default: 0 if t0_wall_utime is set, else the first event)
  Duration progress_period = Duration::fromSec(5.0);  ///< wall time between progress lines (≤ 0: none)
  int64_t max_sleep_us = 50000;          ///< longest single wait, so that a stop request is seen quickly [µs]
  /// A first event due further than this in the future is a mistake (e.g. Unix-epoch data with
  /// data_t0 = 0): run() throws instead of waiting [µs].
  int64_t max_initial_wait_us = 24LL * 3600LL * 1000000LL;
};

/// Counters of a replay, for the progress line and the final summary.
struct ReplayProgress {
  size_t emitted = 0;
  size_t total = 0;
  Timestamp first_data_t;
  Timestamp last_data_t;       ///< data time of the last event of the time line
  Timestamp current_data_t;    ///< data time of the newest emitted event
  int64_t max_lag_us = 0;      ///< worst lateness of an emission w.r.t. its due time [µs]
  int64_t wall_elapsed_us = 0; ///< wall time since the start of run() [µs]
  bool stopped = false;        ///< stopped early by the stop predicate
};

class ReplayScheduler {
 public:
  ReplayScheduler(ReplayOptions options, Clock& clock);

  /// Emits every event of `events` (time-sorted) at its due wall time; returns early when `stop`
  /// returns true (checked at least every `max_sleep_us`). Returns the progress at the end.
  /// Throws std::invalid_argument on a negative rate or an absurd first wait.
  ReplayProgress run(const std::vector<ReplayEvent>& events,
                     const std::function<void(const ReplayEvent&)>& emit,
                     const std::function<bool()>& stop = {});

  /// Wall time at which data time `t` is due, once the time base is fixed (inside run()).
  int64_t dueWallUtime(Timestamp t) const;
  /// Fixes the time base given the first data time and the current wall time (run() calls it).
  void start(Timestamp first_data_t, int64_t now_wall_utime);

  /// Where progress lines go (default: spdlog info).
  void setProgressSink(std::function<void(const std::string&)> sink) { progress_sink_ = std::move(sink); }
  /// "replay 12.3/140.0 s (8.8 %), 1234/5678 msgs, 10x, lag 2.1 ms"
  static std::string formatProgress(const ReplayProgress& p, double rate);

  const ReplayOptions& options() const { return options_; }

 private:
  ReplayOptions options_;
  Clock& clock_;
  int64_t t0_wall_us_ = 0;
  Timestamp t0_data_;
  std::function<void(const std::string&)> progress_sink_;
};

}  // namespace meshnav::replay
