/// @file reentry_gate.cpp
/// @brief ReentryGate: holding, checking and releasing the tag ranges after a gap (reentry_gate.h).

#include "estimator/uwb/reentry_gate.h"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "common/chi_square.h"

namespace meshnav::estimator {

bool ReentryGate::admit(const RangeSample& s, SensorId anchor, const Linearization& lin, const FusionStrategy& filter,
                        Timestamp init_time, bool first, bool* count) {
  const UwbOptions& o = options_;
  if (o.reentry_gap_s <= 0.0) return true;
  // The per-range path: nothing to look up unless a hold is running or has decided fates.
  const bool any_fate = !hold_.decided.empty() || !hold_.held.empty();
  if (!first && !any_fate) return true;
  const InputOrder key{s.t.us, InputKind<RangeSample>::rank, s.id_initiator, s.id_responder};  // = inputOrder(s)
  if (auto d = hold_.decided.find(key); any_fate && d != hold_.decided.end()) {
    if (d->second == Fate::kRejected) return false;
    if (d->second == Fate::kAcceptedUncounted) {
      *count = true;  // its first fusion: counters and health were deferred by the hold
      d->second = Fate::kAccepted;
    }
    return true;
  }
  const auto held = std::find_if(hold_.held.begin(), hold_.held.end(), [&](const auto& h) { return h.first == key; });
  if (held != hold_.held.end()) return false;  // replayed by a rewind while still held
  if (!first) return true;
  ++hold_.n_seen;
  if (!hold_.first_seen) hold_.first_seen = s.t;
  const Timestamp last = last_accepted_.value_or(init_time);
  if (!hold_.since && (s.t - last).sec() < o.reentry_gap_s) return true;
  if (!hold_.since) {
    // Sparse ranging (MILUV: about one tag range per second) fills no hold with enough ranges to
    // test; holding would only delay them. The mean tag-range rate since the first one decides.
    const double span_s = (s.t - *hold_.first_seen).sec();
    if (span_s <= 0.0 || static_cast<double>(hold_.n_seen) / span_s * o.reentry_hold_s < o.reentry_min_ranges) {
      diag_.count("range_reentry_too_sparse");
      return true;
    }
  }
  const NominalState& x = filter.state();
  const JacobianBlock* b = lin.find(x.imu_id);
  if (!b || lin.dim() != 1) return true;
  if (!hold_.since) {
    hold_.since = s.t;
    hold_.P_pp = filter.covariance(x.imu_id, x.imu_id).block<3, 3>(ImuErr::kP, ImuErr::kP);
    diag_.count("range_reentry_hold");
    spdlog::info("estimator: no tag range accepted for {:.2f} s before t={}: holding the next ranges (up to {} s) to "
                 "check them against each other",
                 (s.t - last).sec(), formatSeconds(s.t), o.reentry_hold_s);
  }
  ReentryCheck::Held h;
  h.nu_m = lin.residual(0);
  h.u = b->H.block<1, 3>(0, ImuErr::kP).transpose();
  h.R_m2 = lin.R(0, 0);
  h.anchor = anchor;
  hold_.held.emplace_back(key, h);
  diag_.count("range_reentry_held");
  return false;
}

std::optional<InputOrder> ReentryGate::releaseIfDue(Timestamp newest) {
  if (!hold_.since) return std::nullopt;
  const UwbOptions& o = options_;
  // The whole hold: a check of the first few ranges only leaves the next NLOS range to the single gate.
  if ((newest - *hold_.since).sec() < o.reentry_hold_s) return std::nullopt;
  std::vector<ReentryCheck::Held> hs;
  for (const auto& [key, h] : hold_.held) hs.push_back(h);
  const ReentryCheck::Result res = ReentryCheck::decide(hs, hold_.P_pp, chi2Quantile(1, o.reentry_gate_probability),
                                                        o.reentry_min_ranges, o.reentry_min_anchors);
  std::string rejected;
  for (size_t i = 0; i < hs.size(); ++i) {
    const InputOrder& key = hold_.held[i].first;
    hold_.decided[key] = res.accepted[i] ? Fate::kAcceptedUncounted : Fate::kRejected;
    if (!res.accepted[i])
      rejected += (rejected.empty() ? "" : ", ") + std::to_string(hs[i].anchor) + " at t=" +
                  formatSeconds(Timestamp{key.t_us}) + " (ν " + std::to_string(hs[i].nu_m) + " m)";
  }
  diag_.count(res.checked ? "range_reentry_checked" : "range_reentry_unchecked");
  if (res.rejected > 0) {
    diag_.count("range_reentry_rejected", res.rejected);
    spdlog::warn("estimator: after the gap, {} of {} held ranges disagree with the others and are not fused: {}",
                 res.rejected, hs.size(), rejected);
  }
  const InputOrder first_key = hold_.held.front().first;
  hold_.since.reset();
  hold_.held.clear();
  return first_key;
}

void ReentryGate::forgetFates(Timestamp newest, double window_s, double keep_s) {
  const int64_t oldest_us = newest.us - Duration::fromSec(keep_s + 1.0).us;
  const int64_t oldest_accepted_us = newest.us - Duration::fromSec(window_s + 1.0).us;
  std::erase_if(hold_.decided, [&](const auto& kv) {
    return kv.first.t_us < oldest_us || (kv.second != Fate::kRejected && kv.first.t_us < oldest_accepted_us);
  });
}

void ReentryGate::restart(Timestamp t) {
  hold_ = Hold{};
  last_accepted_ = t;
}

}  // namespace meshnav::estimator
