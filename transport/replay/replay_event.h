#pragma once
/// @file replay_event.h
/// @brief One entry of a replay time line, and the merge of several time-sorted streams into one.

#include <cstddef>
#include <vector>

#include "common/time.h"

namespace meshnav::replay {

/// One sample to emit: its data time, the stream it belongs to and its index in that stream.
struct ReplayEvent {
  Timestamp t;
  int stream = 0;
  size_t index = 0;
};

/// Merges the time stamps of several streams into one time line sorted by time; equal times keep
/// the order of the streams, then the order within a stream (stable), so a replay is deterministic.
/// `stream_times[s][i]` is the time of sample i of stream s (streams need not be sorted).
std::vector<ReplayEvent> mergeTimeline(const std::vector<std::vector<Timestamp>>& stream_times);

/// Convenience: the time stamps `x.t` of a vector of samples.
template <class Sample>
std::vector<Timestamp> timesOf(const std::vector<Sample>& samples) {
  std::vector<Timestamp> out;
  out.reserve(samples.size());
  for (const auto& s : samples) out.push_back(s.t);
  return out;
}

}  // namespace meshnav::replay
