#include "transport/replay/replay_scheduler.h"

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace meshnav::replay {

ReplayScheduler::ReplayScheduler(ReplayOptions options, Clock& clock)
    : options_(std::move(options)), clock_(clock),
      progress_sink_([](const std::string& line) { spdlog::info("{}", line); }) {
  if (!(options_.rate >= 0.0) || !std::isfinite(options_.rate))
    throw std::invalid_argument(fmt::format("replay rate must be >= 0 (0 = as fast as possible), got {}", options_.rate));
}

void ReplayScheduler::start(Timestamp first_data_t, int64_t now_wall_utime) {
  if (options_.t0_wall_utime) {
    t0_wall_us_ = *options_.t0_wall_utime;
    t0_data_ = options_.data_t0.value_or(Timestamp{0});
  } else {
    t0_wall_us_ = now_wall_utime;
    t0_data_ = options_.data_t0.value_or(first_data_t);
  }
}

int64_t ReplayScheduler::dueWallUtime(Timestamp t) const {
  if (options_.rate <= 0.0) return std::numeric_limits<int64_t>::min();
  const double offset_us = static_cast<double>((t - t0_data_).us) / options_.rate;
  return t0_wall_us_ + static_cast<int64_t>(std::llround(offset_us));
}

std::string ReplayScheduler::formatProgress(const ReplayProgress& p, double rate) {
  const double span = (p.last_data_t - p.first_data_t).sec();
  const double done = (p.current_data_t - p.first_data_t).sec();
  const double pct = p.total > 0 ? 100.0 * static_cast<double>(p.emitted) / static_cast<double>(p.total) : 100.0;
  const std::string speed = rate > 0.0 ? fmt::format("{:g}x", rate) : std::string("max speed");
  return fmt::format("replay {:.1f}/{:.1f} s ({:.1f} %), {}/{} msgs, {}, wall {:.1f} s, max lag {:.1f} ms",
                     done, span, pct, p.emitted, p.total, speed, p.wall_elapsed_us * 1e-6,
                     p.max_lag_us * 1e-3);
}

ReplayProgress ReplayScheduler::run(const std::vector<ReplayEvent>& events,
                                    const std::function<void(const ReplayEvent&)>& emit,
                                    const std::function<bool()>& stop) {
  ReplayProgress p;
  p.total = events.size();
  if (events.empty()) return p;
  p.first_data_t = events.front().t;
  p.last_data_t = events.back().t;
  p.current_data_t = p.first_data_t;

  const int64_t wall_start = clock_.nowUtime();
  start(events.front().t, wall_start);
  const bool paced = options_.rate > 0.0;
  if (paced) {
    const int64_t first_wait = dueWallUtime(events.front().t) - wall_start;
    if (first_wait > options_.max_initial_wait_us)
      throw std::invalid_argument(fmt::format(
          "replay: the first sample (data time {:.6f} s) would be played in {:.0f} s; data time "
          "{:.6f} s is mapped to the given wall time t0: give the data time of t0 explicitly "
          "(--data-t0) for data stamped in Unix time",
          events.front().t.sec(), first_wait * 1e-6, t0_data_.sec()));
  }
  int64_t next_progress = wall_start + options_.progress_period.us;

  for (const auto& ev : events) {
    if (paced) {
      const int64_t due = dueWallUtime(ev.t);
      for (int64_t now = clock_.nowUtime(); now < due; now = clock_.nowUtime()) {
        if (stop && stop()) {
          p.stopped = true;
          break;
        }
        clock_.sleepUntil(due, options_.max_sleep_us);
      }
      if (p.stopped) break;
      p.max_lag_us = std::max(p.max_lag_us, clock_.nowUtime() - due);
    }
    if (stop && stop()) {
      p.stopped = true;
      break;
    }
    emit(ev);
    ++p.emitted;
    p.current_data_t = ev.t;
    if (options_.progress_period.us > 0) {
      const int64_t now = clock_.nowUtime();
      if (now >= next_progress) {
        p.wall_elapsed_us = now - wall_start;
        progress_sink_(formatProgress(p, options_.rate));
        next_progress = now + options_.progress_period.us;
      }
    }
  }
  p.wall_elapsed_us = clock_.nowUtime() - wall_start;
  return p;
}

}  // namespace meshnav::replay
