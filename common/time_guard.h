#pragma once
/// @file time_guard.h
/// @brief Keeps a receiver's clock safe from inputs stamped far from its current time (a sensor or
/// host whose clock is off, random bytes behind a valid message fingerprint, a typo in a replay).
///
/// The receiver's *current time* is the newest accepted input time (data time: dataset time in a
/// replay, the senders' clock live). An input farther than `max_offset_s` from it, ahead or behind,
/// is refused (`Verdict::Ahead` / `Verdict::Behind`; behind, the limit may be longer:
/// `max_behind_s`); the caller counts it and drops it, so it never moves the clock. Inputs within the offset are accepted and move the clock forward.
///
/// A real jump of the whole data stream (a recording that pauses, a sender restarted on another
/// epoch, a wrong first input that set the clock) is told apart from a bad input by agreement:
/// when `rebase_after` consecutive inputs are all refused and all lie within `max_offset_s` of
/// each other, the clock moves to them (`Verdict::Rebased`, the input is accepted). One bad sensor
/// among good ones never gets there (every accepted input restarts the count), nor do random time
/// stamps (they do not agree). The first input sets the clock.
///
/// Inputs name their source (admit's `kind`: IMU, RANGE, …; check() without one is a single
/// anonymous source). Once two sources have been accepted, a jump must be agreed on by two of
/// them: a burst from one source alone (100 IMU messages stamped +1 h, issue 36) is that source's
/// fault however long it lasts, refused and reported once per burst as "<kind>:time_jump_alone".
/// A whole stream that jumps carries its other sources along, and the clock follows when the
/// first of them agrees.

#include <cstdint>
#include <optional>
#include <set>
#include <string>

#include "common/diagnostics.h"
#include "common/time.h"

namespace meshnav {

/// Options of a TimeGuard (documented with the estimator and calibrator options that hold them).
struct TimeGuardOptions {
  /// An input farther than this from the current time is refused [s].
  double max_offset_s = 10.0;
  /// This many consecutive refused inputs that agree among themselves move the clock [-].
  int rebase_after = 50;
  /// Behind the current time the limit is the larger of this and `max_offset_s` (a receiver that
  /// keeps a longer history, like the calibrator's pose history) [s].
  double max_behind_s = 0.0;
  /// Throws std::invalid_argument naming the option ("max_offset_s > 0", "rebase_after >= 1").
  void validate() const;
};

class TimeGuard {
 public:
  enum class Verdict { Accept, Ahead, Behind, Rebased };

  explicit TimeGuard(TimeGuardOptions options = {});
  /// Checks an input stamped `t` (any int64 utime: no overflow) from `source` and updates the
  /// current time.
  Verdict check(Timestamp t, const std::string& source = "");
  /// check() for an input of `kind` (its channel name), reporting to `diag`: a refusal as
  /// "<kind>:time_ahead" / "<kind>:time_behind", a rebase as "time_rebased", each with a message
  /// naming the times. Returns the verdict (Ahead/Behind: drop the input).
  Verdict admit(const std::string& kind, Timestamp t, Diagnostics& diag);
  /// The current time (newest accepted input), nullopt before the first input.
  std::optional<Timestamp> now() const { return now_; }
  /// Clock change of the last `Rebased` verdict (new − old current time).
  Duration lastJump() const { return last_jump_; }
  /// Forgets the current time (the next input sets it).
  void reset();
  const TimeGuardOptions& options() const { return options_; }
  /// "ahead" / "behind" / "accepted" / "rebased" (for counters and messages).
  static const char* name(Verdict v);

 private:
  TimeGuardOptions options_;
  int64_t max_offset_us_, max_behind_us_;
  std::optional<Timestamp> now_;
  int streak_ = 0;                 ///< consecutive refused inputs that agree
  int64_t streak_lo_ = 0, streak_hi_ = 0;  ///< their time span [µs]
  std::set<std::string> streak_sources_;   ///< their sources
  std::set<std::string> sources_;          ///< every source with an accepted input
  bool alone_reported_ = false;            ///< this streak was reported as one source's jump
  Duration last_jump_;
};

}  // namespace meshnav
