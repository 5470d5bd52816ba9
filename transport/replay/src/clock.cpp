#include "transport/replay/clock.h"

#include <algorithm>
#include <chrono>
#include <thread>

namespace meshnav::replay {

int64_t wallUtimeNow() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

int64_t monotonicUsNow() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

int64_t SystemClock::nowUtime() { return wallUtimeNow(); }

void SystemClock::sleepUntil(int64_t wall_utime, int64_t max_wait_us) {
  const int64_t wait = std::min(wall_utime - nowUtime(), max_wait_us);
  if (wait > 0) std::this_thread::sleep_for(std::chrono::microseconds(wait));
}

}  // namespace meshnav::replay
