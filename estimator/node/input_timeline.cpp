/// @file input_timeline.cpp
/// @brief InputTimeline: the window of stored inputs and the archive kept for re-runs.
#include "estimator/node/input_timeline.h"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace meshnav::estimator {

namespace {
/// Checkpoints per `refine.max_history_s`: the archive is cut in steps of this fraction.
constexpr double kCheckpointsPerHistory = 8.0;
}  // namespace

InputTimeline::InputTimeline(double window_s, const RefineOptions& refine, bool keep_archive, Diagnostics& diag)
    : window_s_(window_s), refine_(refine), keep_archive_(keep_archive), diag_(diag) {}

void InputTimeline::restart(Timestamp t) {
  window_.clear();
  clearArchive();
  start_ = t;
}

void InputTimeline::clear() {
  window_.clear();
  clearArchive();
}

void InputTimeline::clearArchive() {
  archive_.clear();
  last_checkpoint_.reset();
}

bool InputTimeline::beforeWindow(Timestamp t) const {
  return newest_ && t < *newest_ - Duration::fromSec(window_s_);
}

InputTimeline::Window::iterator InputTimeline::placeOf(const InputOrder& key) {
  return std::upper_bound(window_.begin(), window_.end(), key,
                          [](const InputOrder& k, const Entry& x) { return k < x.key; });
}

InputTimeline::Window::iterator InputTimeline::find(const InputOrder& key) {
  return std::find_if(window_.begin(), window_.end(), [&](const Entry& e) { return e.key == key; });
}

int64_t InputTimeline::oldestReplayUs(int64_t newest_us) const {
  const double keep_s = keep_archive_ ? refine_.max_history_s : window_s_;
  return newest_us - Duration::fromSec(keep_s + 1.0).us;
}

void InputTimeline::retire(Timestamp oldest_kept) {
  const Duration interval = Duration::fromSec(refine_.max_history_s / kCheckpointsPerHistory);
  while (!window_.empty() && window_.front().key.t_us < oldest_kept.us) {
    Entry& e = window_.front();
    if (keep_archive_) {
      const Timestamp t{e.key.t_us};
      const bool checkpoint = archive_.empty() || !last_checkpoint_ || t - *last_checkpoint_ >= interval;
      if (checkpoint) last_checkpoint_ = t;
      archive_.push_back({e.key, std::move(e.input), checkpoint ? std::move(e.before) : nullptr});
    }
    window_.pop_front();
  }
  if (archive_.empty() || !newest_) return;
  const int64_t limit_us = newest_->us - Duration::fromSec(refine_.max_history_s).us;
  if (archive_.front().key.t_us >= limit_us) return;
  // Cut to the next checkpoint at or after the limit: a re-run needs the state before its first input.
  int64_t dropped = 0;
  while (!archive_.empty() && (archive_.front().key.t_us < limit_us || !archive_.front().checkpoint)) {
    archive_.pop_front();
    ++dropped;
  }
  if (archive_.empty()) last_checkpoint_.reset();
  diag_.count("rerun_history_cut");
  diag_.count("rerun_inputs_cut", dropped);
  spdlog::info("estimator: re-run history cut at t={} (refine.max_history_s {} s): {} inputs dropped, re-runs start at t={}",
               formatSeconds(*newest_), refine_.max_history_s, dropped,
               archive_.empty() ? std::string("the out-of-sequence window")
                                : formatSeconds(Timestamp{archive_.front().key.t_us}));
}

}  // namespace meshnav::estimator
