#pragma once
/// @file input_timeline.h
/// @brief InputTimeline: the inputs the node has processed since its initialization, each with the
/// FilterContext before it, so that a late input can be put in its place and everything after it
/// re-processed (a rewind), and the older inputs kept for a re-run on an anchor join (AnchorRerun).
///
/// - The window: every input newer than `newest − window_s`, time-sorted by InputOrder, each with
///   the context before it. An input older than the window, or older than the initialization
///   (`start`), is not admitted.
/// - The archive (re-runs on only): inputs that left the window, up to `refine.max_history_s`.
///   Every eighth of that span one keeps the context before it (a checkpoint), and the oldest always
///   does: the re-run's starting state. The archive is cut from the front, to the next checkpoint,
///   counted "rerun_history_cut" and "rerun_inputs_cut".
/// A re-initialization (`restart`) forgets both: no rewind or re-run may restore a state before it.

#include <deque>
#include <memory>
#include <optional>

#include "common/diagnostics.h"
#include "common/types.h"
#include "estimator/core/estimator_options.h"
#include "estimator/node/estimator_input.h"
#include "estimator/node/filter_context.h"

namespace meshnav::estimator {

class InputTimeline {
 public:
  struct Entry {
    InputOrder key;
    EstimatorInput input;
    std::shared_ptr<const FilterContext> before;
  };
  /// An input older than the window, kept for re-runs; `checkpoint`: the context before it, or null.
  struct Archived {
    InputOrder key;
    EstimatorInput input;
    std::shared_ptr<const FilterContext> checkpoint;
  };
  using Window = std::deque<Entry>;

  /// `keep_archive`: re-runs are on (inputs leaving the window are archived).
  InputTimeline(double window_s, const RefineOptions& refine, bool keep_archive, Diagnostics& diag);

  /// The newest input time seen (also before the initialization); empty after a start-over.
  const std::optional<Timestamp>& newest() const { return newest_; }
  void advance(Timestamp t) { newest_ = newest_ ? std::max(*newest_, t) : t; }
  void forgetNewest() { newest_.reset(); }
  /// The time of the initialization (or re-initialization): older inputs are not processed.
  Timestamp start() const { return start_; }
  /// A (re-)initialization at `t`: window and archive forgotten.
  void restart(Timestamp t);
  /// Forgets every stored input (a reset by command or a start-over), keeping `start`.
  void clear();
  /// Forgets the archive only.
  void clearArchive();

  /// `t` is older than the window behind the newest input.
  bool beforeWindow(Timestamp t) const;
  Window& window() { return window_; }
  const Window& window() const { return window_; }
  std::deque<Archived>& archive() { return archive_; }
  const std::deque<Archived>& archive() const { return archive_; }
  /// The first stored input after `key` (where an input of that key goes).
  Window::iterator placeOf(const InputOrder& key);
  Window::iterator find(const InputOrder& key);
  /// Moves inputs older than `oldest_kept` out of the window (into the archive when it is kept)
  /// and cuts the archive to `refine.max_history_s` behind the newest input.
  void retire(Timestamp oldest_kept);
  /// How far back (from `newest_us`) a replay may reach [µs]: the stillness it needs is kept that long.
  int64_t oldestReplayUs(int64_t newest_us) const;

 private:
  double window_s_;
  RefineOptions refine_;
  bool keep_archive_;
  Diagnostics& diag_;
  std::optional<Timestamp> newest_;
  Timestamp start_;
  Window window_;
  std::deque<Archived> archive_;
  std::optional<Timestamp> last_checkpoint_;  ///< time of the newest checkpoint in archive_
};

}  // namespace meshnav::estimator
