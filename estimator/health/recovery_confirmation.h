#pragma once
/// @file recovery_confirmation.h
/// @brief Whether a re-initialization was confirmed by the measurements after it (issue 36).
///
/// A recovery replaces the filter's pose with an alignment from the last window of ranges. That
/// pose may be the wrong one of two that fit alike (a mirror image, a heading off by the ambiguity
/// of a one-tag fit): "recovered" is a claim the later ranges must back. It counts as confirmed
/// once health has been `ok` without interruption for at least a statistics window
/// (`health.window_s`) and the tag ranges accepted since health last became ok (counted here, not
/// in the monitor's window: one range per 1.2 s, as on MILUV, never fills a window) number at
/// least `health.min_ranges` with a mean NIS within `health.degraded_mean_nis` (E[NIS] = 1). A new
/// recovery before that replaces the pending one. A monitor like the others: not rewound with
/// the filter.

#include <optional>

#include "common/time.h"
#include "estimator/health/health_monitor.h"

namespace meshnav::estimator {

class RecoveryConfirmation {
 public:
  explicit RecoveryConfirmation(const HealthOptions& o)
      : window_s_(o.window_s), min_ranges_(o.min_ranges), max_mean_nis_(o.degraded_mean_nis) {}

  /// A recovery at `t` (health is `ok` from there: the monitor's window restarted).
  void noteRecovery(Timestamp t) {
    pending_ = t;
    restart(t);
  }
  /// A tag range through the update: accepted, with its NIS.
  void noteRange(bool accepted, double nis) {
    if (!pending_ || !ok_since_ || !accepted) return;
    ++n_;
    nis_sum_ += nis;
  }
  /// Health `h` evaluated at `t`; returns true when this confirms the pending recovery.
  bool noteHealth(Timestamp t, Health h) {
    if (!pending_) return false;
    if (h != Health::Ok) {  // interrupted: the count starts again when health is ok again
      ok_since_.reset();
      n_ = 0;
      nis_sum_ = 0.0;
      return false;
    }
    if (!ok_since_) restart(t);
    if ((t - *ok_since_).sec() < window_s_ || n_ < min_ranges_ || nis_sum_ > max_mean_nis_ * n_) return false;
    pending_.reset();
    return true;
  }
  /// Accepted ranges since health last became ok, and their mean NIS.
  int rangesFitted() const { return n_; }
  double meanNis() const { return n_ ? nis_sum_ / n_ : 0.0; }
  /// The time of a recovery not confirmed yet.
  std::optional<Timestamp> pending() const { return pending_; }
  /// How long health has been `ok` since the pending recovery's latest interruption, at `t` [s].
  double okFor(Timestamp t) const { return ok_since_ ? (t - *ok_since_).sec() : 0.0; }
  void reset() {
    pending_.reset();
    ok_since_.reset();
  }

 private:
  void restart(Timestamp t) {
    ok_since_ = t;
    n_ = 0;
    nis_sum_ = 0.0;
  }
  double window_s_;
  int min_ranges_;
  double max_mean_nis_;
  std::optional<Timestamp> pending_, ok_since_;
  int n_ = 0;
  double nis_sum_ = 0.0;
};

}  // namespace meshnav::estimator
