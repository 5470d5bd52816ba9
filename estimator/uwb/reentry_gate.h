#pragma once
/// @file reentry_gate.h
/// @brief Tag ranges after an aiding gap (UwbOptions reentry_*, docs/robustness.md "Range gaps").
///
/// The model: after `uwb.reentry_gap_s` without an accepted tag range the position prior is wide
/// enough for one NLOS range to pass its own χ² gate. The next tag ranges are therefore held (not
/// fused, their innovation and position row kept), tested against each other by ReentryCheck once
/// `uwb.reentry_hold_s` passed, and the node rewinds to the first held range and re-processes the
/// history, fusing the agreeing ones at their own times (the out-of-sequence machinery). Every
/// held range's fate is kept by its key so that rewinds and re-runs replay the same decision.
/// With sparse ranging (fewer than `reentry_min_ranges` per hold at the mean tag-range rate) a hold
/// could not test anything: ranges go straight through ("range_reentry_too_sparse").

#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "common/diagnostics.h"
#include "estimator/core/estimator_options.h"
#include "estimator/core/linearization.h"
#include "estimator/filter/fusion_strategy.h"
#include "estimator/node/estimator_input.h"
#include "estimator/uwb/reentry_check.h"

namespace meshnav::estimator {

class ReentryGate {
 public:
  ReentryGate(const UwbOptions& options, Diagnostics& diag) : options_(options), diag_(diag) {}

  /// For a tag range `s` to `anchor`, linearized as `lin` on `filter`: true when it is fused now.
  /// False when held (first pass) or rejected by an earlier check, or replayed while still held.
  /// `*count` is set when a released range is fused for the first time (its counters and health
  /// were deferred by the hold). `first`: the range's first processing (not a replay).
  /// `init_time`: the filter's initialization (the gap's start when no range was accepted yet).
  bool admit(const RangeSample& s, SensorId anchor, const Linearization& lin, const FusionStrategy& filter,
             Timestamp init_time, bool first, bool* count);
  /// A tag range was accepted at `t` (a gap is measured from the last one).
  void noteAccepted(Timestamp t) { last_accepted_ = t; }
  /// Ranges are held now (the node defers its health evaluation meanwhile).
  bool holding() const { return hold_.since.has_value(); }
  /// When the hold is over at `newest`: checks the held ranges against each other, records their
  /// fates and returns the first held range's key, from which the node must re-process. Nullopt
  /// while holding or when nothing is held.
  std::optional<InputOrder> releaseIfDue(Timestamp newest);
  /// Forgets fates older than needed: accepted ones after `window_s` + 1 s, rejected ones after
  /// `keep_s` (the longer of the window and a re-run's history) + 1 s.
  void forgetFates(Timestamp newest, double window_s, double keep_s);
  /// Forgets everything; `t` becomes the last accepted time (a re-initialization from ranges).
  void restart(Timestamp t);
  /// Forgets everything and the last accepted time (a reset of the node).
  void reset() {
    hold_ = Hold{};
    last_accepted_.reset();
  }
  /// The replay node of a re-run: rejected fates stay out, held ones wait for the live release.
  void copyFatesFrom(const ReentryGate& live) {
    hold_.decided = live.hold_.decided;
    hold_.held = live.hold_.held;
  }

 private:
  enum class Fate { kRejected, kAcceptedUncounted, kAccepted };
  struct Hold {
    std::optional<Timestamp> since;  ///< time of the first held range (holding while set)
    std::vector<std::pair<InputOrder, ReentryCheck::Held>> held;
    Eigen::Matrix3d P_pp = Eigen::Matrix3d::Zero();  ///< position covariance at the first held range [m²]
    std::map<InputOrder, Fate> decided;
    int64_t n_seen = 0;  ///< tag ranges seen live (their mean rate decides whether a hold can check)
    std::optional<Timestamp> first_seen;
  };
  const UwbOptions& options_;
  Diagnostics& diag_;
  Hold hold_;
  std::optional<Timestamp> last_accepted_;
};

}  // namespace meshnav::estimator
