#include "transport/replay/replay_event.h"

#include <algorithm>

namespace meshnav::replay {

std::vector<ReplayEvent> mergeTimeline(const std::vector<std::vector<Timestamp>>& stream_times) {
  std::vector<ReplayEvent> events;
  size_t n = 0;
  for (const auto& s : stream_times) n += s.size();
  events.reserve(n);
  for (size_t s = 0; s < stream_times.size(); ++s)
    for (size_t i = 0; i < stream_times[s].size(); ++i)
      events.push_back(ReplayEvent{stream_times[s][i], static_cast<int>(s), i});
  std::stable_sort(events.begin(), events.end(),
                   [](const ReplayEvent& a, const ReplayEvent& b) { return a.t < b.t; });
  return events;
}

}  // namespace meshnav::replay
