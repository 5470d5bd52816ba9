/// @file estimator_node_rerun.cpp
/// @brief EstimatorNode, the second pass of issue 10 (RefineOptions, docs/modular_estimator.md,
/// "Re-run on anchor join"): inputs older than the out-of-sequence window are archived up to
/// `refine.max_history_s`; when a calibrated anchor joins (ANCHOR_INIT), the node restores the
/// oldest stored state, adds every calibrated anchor there with a loose prior around its
/// calibration and re-processes all stored inputs, so the anchors are estimated jointly with the
/// trajectory from the start instead of from the (already wrong) trajectory after their join.

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>

#include "estimator/node/estimator_node.h"

namespace meshnav::estimator {

namespace {
/// Checkpoints per `refine.max_history_s`: the history is cut in steps of this fraction.
constexpr double kCheckpointsPerHistory = 8.0;
}  // namespace

void EstimatorNode::applyPendingAnchorInits(Timestamp t) {
  const auto pending = std::move(pending_anchor_inits_);
  pending_anchor_inits_.clear();
  applying_pending_inits_ = true;  // resumed or early anchors keep their covariance (no re-run)
  for (auto a : pending) {
    a.t = t;
    onInput(a);
  }
  applying_pending_inits_ = false;
}

void EstimatorNode::clearRerunHistory() {
  archive_.clear();
  last_checkpoint_.reset();
}

int64_t EstimatorNode::oldestReplayUs(int64_t newest_us) const {
  const double keep_s = rerun_enabled_ ? options_.refine.max_history_s : options_.window_s;
  return newest_us - Duration::fromSec(keep_s + 1.0).us;
}

void EstimatorNode::retireHistory(Timestamp oldest_kept) {
  const bool keep = rerun_enabled_;
  const Duration interval = Duration::fromSec(options_.refine.max_history_s / kCheckpointsPerHistory);
  while (!history_.empty() && history_.front().key.t_us < oldest_kept.us) {
    Entry& e = history_.front();
    if (keep) {
      const Timestamp t{e.key.t_us};
      const bool checkpoint = archive_.empty() || !last_checkpoint_ || t - *last_checkpoint_ >= interval;
      if (checkpoint) last_checkpoint_ = t;
      archive_.push_back({e.key, std::move(e.input), checkpoint ? std::move(e.before) : nullptr});
    }
    history_.pop_front();
  }
  if (archive_.empty() || !newest_) return;
  const int64_t limit_us = newest_->us - Duration::fromSec(options_.refine.max_history_s).us;
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
               formatSeconds(*newest_), options_.refine.max_history_s, dropped,
               archive_.empty() ? std::string("the out-of-sequence window")
                                : formatSeconds(Timestamp{archive_.front().key.t_us}));
}

bool EstimatorNode::skipReplayedAnchorInit(const AnchorInit& a, bool first) const {
  if (first || !rerun_enabled_ || !cur_.filter->state().values<AnchorKind>().count(a.id)) return false;
  return std::any_of(rerun_anchors_.begin(), rerun_anchors_.end(), [&](const AnchorInit& r) { return r.id == a.id; });
}

void EstimatorNode::noteAnchorJoin(const AnchorInit& a, bool first) {
  if (!first || !rerun_enabled_ || applying_pending_inits_ ||
      !cur_.filter->state().values<AnchorKind>().count(a.id))
    return;
  std::erase_if(rerun_anchors_, [&](const AnchorInit& r) { return r.id == a.id; });
  rerun_anchors_.push_back(a);
  rerun_pending_ = true;
}

AnchorInit EstimatorNode::loosePrior(const AnchorInit& a, Timestamp t) const {
  AnchorInit l = a;
  l.t = t;
  l.cov_p_m2 = Eigen::Matrix3d::Identity() * options_.refine.rerun_prior_sigma_m * options_.refine.rerun_prior_sigma_m;
  l.cov_gamma_p_m2.resize(0, 0);
  l.cov_gamma_m2.resize(0, 0);
  for (PairBias& b : l.biases)
    if (b.sigma_gamma_m > 0.0) {
      b.sigma_gamma_m = options_.refine.rerun_gamma_sigma_m;
      if (!options_.refine.rerun_gamma_from_calibration) b.gamma_m = 0.0;
    }
  return l;
}

void EstimatorNode::rerunFromOldest() {
  rerun_pending_ = false;
  const std::shared_ptr<const Snapshot> base = !archive_.empty() ? archive_.front().checkpoint
                                               : history_.empty()  ? nullptr
                                                                   : history_.front().before;
  if (!base || !base->filter) {
    diag_.count("rerun_skipped");  // nothing stored (e.g. right after a re-initialization)
    return;
  }
  const auto wall0 = std::chrono::steady_clock::now();
  ScopedStepTimer timer(timings_, "rerun");
  cur_ = base->copy();
  const Timestamp t0 = cur_.filter->state().t;
  std::string ids;
  for (const AnchorInit& a : rerun_anchors_) {
    if (cur_.filter->state().values<AnchorKind>().count(a.id)) continue;  // from an earlier re-run's checkpoint
    applyAnchorInit(loosePrior(a, t0), false);
    ids += (ids.empty() ? "" : ", ") + std::to_string(a.id);
  }
  int64_t n = 0;
  for (auto it = archive_.begin(); it != archive_.end(); ++it, ++n) {
    if (it != archive_.begin() && it->checkpoint) it->checkpoint = std::make_shared<const Snapshot>(cur_.copy());
    process(it->input, false);
  }
  for (Entry& e : history_) {  // the out-of-sequence window: a later rewind must restore re-run states
    e.before = std::make_shared<const Snapshot>(cur_.copy());
    process(e.input, false);
    ++n;
  }
  const double wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall0).count();
  diag_.count("rerun");
  diag_.count("rerun_inputs", n);
  spdlog::info("estimator: re-run from t={} over {} inputs ({:.1f} s of data), anchors [{}] uncertain from there "
               "(σ {} m around their calibration): {:.1f} ms wall",
               formatSeconds(t0), n, (cur_.filter->state().t - t0).sec(), ids, options_.refine.rerun_prior_sigma_m,
               wall_ms);
}

}  // namespace meshnav::estimator
