#include "common/time_guard.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace meshnav {

namespace {
/// |a − b| ≤ limit without overflow for any int64 pair.
bool within(int64_t a, int64_t b, int64_t limit) {
  const __int128 d = static_cast<__int128>(a) - static_cast<__int128>(b);
  return d <= limit && d >= -static_cast<__int128>(limit);
}
}  // namespace

void TimeGuardOptions::validate() const {
  if (!(max_offset_s > 0.0 && max_offset_s <= kMaxTimeSeconds))
    throw std::invalid_argument("invalid option: max_offset_s > 0 (time guard) [s]");
  if (rebase_after < 1) throw std::invalid_argument("invalid option: rebase_after >= 1 (time guard)");
  if (!(max_behind_s >= 0.0 && max_behind_s <= kMaxTimeSeconds))
    throw std::invalid_argument("invalid option: max_behind_s >= 0 (time guard) [s]");
}

TimeGuard::TimeGuard(TimeGuardOptions options) : options_(options) {
  options_.validate();
  max_offset_us_ = Duration::fromSec(options_.max_offset_s).us;
  max_behind_us_ = std::max(max_offset_us_, Duration::fromSec(options_.max_behind_s).us);
}

void TimeGuard::reset() {
  now_.reset();
  streak_ = 0;
  streak_sources_.clear();
  sources_.clear();
}

const char* TimeGuard::name(Verdict v) {
  switch (v) {
    case Verdict::Accept: return "accepted";
    case Verdict::Ahead: return "ahead";
    case Verdict::Behind: return "behind";
    case Verdict::Rebased: return "rebased";
  }
  return "?";
}

TimeGuard::Verdict TimeGuard::admit(const std::string& kind, Timestamp t, Diagnostics& diag) {
  const std::optional<Timestamp> before = now_;
  const Verdict v = check(t, kind);
  if (v == Verdict::Ahead || v == Verdict::Behind)
    diag.report(kind + ":time_" + name(v), kind + " t=" + formatSeconds(t) + " is " + name(v) + " of the current time " +
                                               formatSeconds(*before) + " by more than the limit (" +
                                               std::to_string(options_.max_offset_s) + " s" +
                                               (v == Verdict::Behind && options_.max_behind_s > options_.max_offset_s
                                                    ? ", behind " + std::to_string(options_.max_behind_s) + " s"
                                                    : std::string()) +
                                               "); refused");
  if ((v == Verdict::Ahead || v == Verdict::Behind) && streak_ >= options_.rebase_after && !alone_reported_) {
    alone_reported_ = true;
    diag.report(kind + ":time_jump_alone",
                std::to_string(streak_) + " consecutive " + kind + " inputs agree on a time near " + formatSeconds(t) +
                    " s, " + name(v) + " of the current time " + formatSeconds(*before) +
                    ", and no other source does: refused as " + kind + "'s fault, the clock stays");
  }
  if (v == Verdict::Rebased)
    diag.report("time_rebased", std::to_string(options_.rebase_after) + " consecutive inputs (the last: " + kind +
                                    ") agree on a time " + std::to_string(last_jump_.sec()) + " s from the current time " +
                                    formatSeconds(*before) + ": the clock follows them");
  return v;
}

TimeGuard::Verdict TimeGuard::check(Timestamp t, const std::string& source) {
  if (!now_) {
    now_ = t;
    sources_.insert(source);
    return Verdict::Accept;
  }
  if (t >= *now_ ? within(t.us, now_->us, max_offset_us_) : within(t.us, now_->us, max_behind_us_)) {
    now_ = std::max(*now_, t);
    streak_ = 0;
    sources_.insert(source);
    return Verdict::Accept;
  }
  // Refused, unless it completes a run of refused inputs that agree among themselves.
  const int64_t lo = streak_ ? std::min(streak_lo_, t.us) : t.us;
  const int64_t hi = streak_ ? std::max(streak_hi_, t.us) : t.us;
  if (streak_ && within(hi, lo, max_offset_us_)) {
    ++streak_;
    streak_lo_ = lo;
    streak_hi_ = hi;
  } else {
    streak_ = 1;
    streak_lo_ = streak_hi_ = t.us;
    streak_sources_.clear();
    alone_reported_ = false;
  }
  streak_sources_.insert(source);
  const Verdict refused = t > *now_ ? Verdict::Ahead : Verdict::Behind;
  if (streak_ < options_.rebase_after) return refused;
  // Agreement across sources once there are two (one source's burst is its own fault).
  const size_t sources_needed = std::min<size_t>(2, sources_.size());
  if (streak_sources_.size() < sources_needed) return refused;
  const __int128 jump = static_cast<__int128>(streak_hi_) - now_->us;
  last_jump_ = Duration{static_cast<int64_t>(std::clamp<__int128>(jump, INT64_MIN, INT64_MAX))};
  now_ = Timestamp{streak_hi_};
  streak_ = 0;
  sources_.insert(source);
  return Verdict::Rebased;
}

}  // namespace meshnav
