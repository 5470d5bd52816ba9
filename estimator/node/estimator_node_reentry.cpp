/// @file estimator_node_reentry.cpp
/// @brief EstimatorNode: tag ranges after an aiding gap (UwbOptions reentry_*, ReentryCheck,
/// docs/robustness.md "Range gaps"). After `uwb.reentry_gap_s` without an accepted tag range the
/// position prior is wide enough for one NLOS range to pass its own gate; the next ranges are held
/// (not fused, their innovations kept), tested against each other once enough arrived or
/// `uwb.reentry_hold_s` passed, and the node rewinds to the first held one and re-processes the
/// history, fusing the agreeing ranges at their own times (the out-of-sequence machinery).

#include <spdlog/spdlog.h>

#include <algorithm>

#include "common/chi_square.h"
#include "estimator/node/estimator_node.h"
#include "estimator/node/node_internals.h"

namespace meshnav::estimator {

bool EstimatorNode::reentryAdmit(const RangeSample& s, SensorId anchor, const Linearization& lin, bool first,
                                 bool* count) {
  const UwbOptions& o = options_.uwb;
  if (o.reentry_gap_s <= 0.0) return true;
  // The per-range path: nothing to look up unless a hold is running or has decided fates.
  const bool any_fate = !reentry_.decided.empty() || !reentry_.held.empty();
  if (!first && !any_fate) return true;
  const InputOrder key{s.t.us, InputKind<RangeSample>::rank, s.id_initiator, s.id_responder};  // = inputOrder(s)
  if (auto d = reentry_.decided.find(key); any_fate && d != reentry_.decided.end()) {
    if (d->second == HeldFate::kRejected) return false;
    if (d->second == HeldFate::kAcceptedUncounted) {
      *count = true;  // its first fusion: counters and health were deferred by the hold
      d->second = HeldFate::kAccepted;
    }
    return true;
  }
  const auto held = std::find_if(reentry_.held.begin(), reentry_.held.end(), [&](const auto& h) { return h.first == key; });
  if (held != reentry_.held.end()) return false;  // replayed by a rewind while still held
  if (!first) return true;
  ++reentry_.n_seen;
  if (!reentry_.first_seen) reentry_.first_seen = s.t;
  const Timestamp last = last_tag_range_accepted_.value_or(init_time_);
  if (!reentry_.since && (s.t - last).sec() < o.reentry_gap_s) return true;
  if (!reentry_.since) {
    // Sparse ranging (MILUV: about one tag range per second) fills no hold with enough ranges to
    // test; holding would only delay them. The mean tag-range rate since the first one decides.
    const double span_s = (s.t - *reentry_.first_seen).sec();
    if (span_s <= 0.0 || static_cast<double>(reentry_.n_seen) / span_s * o.reentry_hold_s < o.reentry_min_ranges) {
      diag_.count("range_reentry_too_sparse");
      return true;
    }
  }
  const NominalState& x = cur_.filter->state();
  const JacobianBlock* b = lin.find(x.imu_id);
  if (!b || lin.dim() != 1) return true;
  if (!reentry_.since) {
    reentry_.since = s.t;
    reentry_.P_pp = cur_.filter->covariance(x.imu_id, x.imu_id).block<3, 3>(ImuErr::kP, ImuErr::kP);
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
  reentry_.held.emplace_back(key, h);
  diag_.count("range_reentry_held");
  return false;
}

void EstimatorNode::releaseReentryIfDue() {
  if (!reentry_.since) return;
  const UwbOptions& o = options_.uwb;
  // The whole hold: a check of the first few ranges only leaves the next NLOS range to the single gate.
  if ((*newest_ - *reentry_.since).sec() < o.reentry_hold_s) return;
  std::vector<ReentryCheck::Held> hs;
  for (const auto& [key, h] : reentry_.held) hs.push_back(h);
  const ReentryCheck::Result res = ReentryCheck::decide(hs, reentry_.P_pp, chi2Quantile(1, o.reentry_gate_probability),
                                                        o.reentry_min_ranges, o.reentry_min_anchors);
  std::string rejected;
  for (size_t i = 0; i < hs.size(); ++i) {
    const InputOrder& key = reentry_.held[i].first;
    reentry_.decided[key] = res.accepted[i] ? HeldFate::kAcceptedUncounted : HeldFate::kRejected;
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
  const InputOrder first_key = reentry_.held.front().first;
  reentry_.since.reset();
  reentry_.held.clear();
  const auto it = std::find_if(history_.begin(), history_.end(), [&](const Entry& e) { return e.key == first_key; });
  if (it == history_.end()) {
    diag_.count("range_reentry_lost");  // cannot happen with reentry_hold_s <= window_s; counted if it does
  } else {
    cur_ = it->before->copy();
    process(it->input, false);
    replayAfter(it);
  }
  // Fates are needed while a rewind or a re-run may replay their range; rejected ones as long as a re-run.
  const double keep_s = std::max(options_.window_s, rerun_enabled_ ? options_.refine.max_history_s : 0.0) + 1.0;
  const int64_t oldest_us = newest_->us - Duration::fromSec(keep_s).us;
  const int64_t oldest_accepted_us = newest_->us - Duration::fromSec(options_.window_s + 1.0).us;
  std::erase_if(reentry_.decided, [&](const auto& kv) {
    return kv.first.t_us < oldest_us || (kv.second != HeldFate::kRejected && kv.first.t_us < oldest_accepted_us);
  });
}

}  // namespace meshnav::estimator
