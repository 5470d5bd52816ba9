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

#include "estimator/node/estimator_node_rerun.h"

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
  abandonRerun();  // its base is gone too
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
  if (rerun_) diag_.count("rerun_queued");  // runs after the current one, with every joined anchor
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

void EstimatorNode::startRerun() {
  rerun_pending_ = false;
  const auto t_job = std::chrono::steady_clock::now();
  std::optional<RerunJob> job = makeRerunJob();
  if (!job) {
    diag_.count("rerun_skipped");  // nothing stored (e.g. right after a re-initialization)
    return;
  }
  diag_.count("rerun");
  diag_.count("rerun_inputs", static_cast<int64_t>(job->inputs.size()));
  if (rerun_async_) {
    launchRerun(std::move(*job), t_job);
    return;
  }
  ScopedStepTimer timer(timings_, "rerun");
  const std::atomic<bool> never{false};
  RerunResult r = computeRerun(std::move(*job), never);
  applyRerun(r, std::nullopt);  // inline: every stored input is the job's own, nothing to re-process
  logRerun(r, "");
}

std::optional<EstimatorNode::RerunJob> EstimatorNode::makeRerunJob() const {
  const bool from_archive = !archive_.empty();
  RerunJob job;
  job.base = from_archive ? archive_.front().checkpoint : history_.empty() ? nullptr : history_.front().before;
  if (!job.base || !job.base->filter) return std::nullopt;
  job.base_key = from_archive ? archive_.front().key : history_.front().key;
  const Timestamp t0 = job.base->filter->state().t;
  for (const AnchorInit& a : rerun_anchors_) job.priors.push_back(loosePrior(a, t0));
  const size_t n = archive_.size() + history_.size();
  job.keys.reserve(n);
  job.inputs.reserve(n);
  job.keep_before.reserve(n);
  for (const Archived& a : archive_) {
    job.keys.push_back(a.key);
    job.inputs.push_back(a.input);
    job.keep_before.push_back(a.checkpoint && a.key != job.base_key);  // the base stays the state without them
  }
  for (const Entry& e : history_) {  // the out-of-sequence window: a later rewind must restore re-run states
    job.keys.push_back(e.key);
    job.inputs.push_back(e.input);
    job.keep_before.push_back(1);
  }
  return job;
}

EstimatorNode::RerunResult EstimatorNode::computeRerun(RerunJob job, const std::atomic<bool>& cancel) {
  const auto wall0 = std::chrono::steady_clock::now();
  RerunResult r;
  r.base_key = job.base_key;
  cur_ = job.base->copy();
  r.t0 = cur_.filter->state().t;
  for (const AnchorInit& a : job.priors) {
    if (cur_.filter->state().values<AnchorKind>().count(a.id)) continue;  // from an earlier re-run's checkpoint
    applyAnchorInit(a, false);
    r.ids += (r.ids.empty() ? "" : ", ") + std::to_string(a.id);
  }
  for (size_t i = 0; i < job.inputs.size(); ++i) {
    if (cancel.load(std::memory_order_relaxed)) {
      r.cancelled = true;
      break;
    }
    if (job.keep_before[i]) r.before.emplace(job.keys[i], std::make_shared<const Snapshot>(cur_.copy()));
    process(job.inputs[i], false);
  }
  r.t_end = cur_.filter->state().t;
  r.state = std::move(cur_);
  r.keys = std::move(job.keys);
  r.wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall0).count();
  return r;
}

std::optional<int64_t> EstimatorNode::applyRerun(RerunResult& r, std::optional<InputOrder> divergence) {
  using SnapshotPtr = std::shared_ptr<const Snapshot>;
  // The job's own stored inputs: up to its newest, before any input inserted among them meanwhile.
  auto own = [&](const InputOrder& k) { return !r.keys.empty() && k <= r.keys.back() && (!divergence || k < *divergence); };
  auto lookup = [&](const InputOrder& k, SnapshotPtr& out) {
    const auto it = r.before.find(k);
    if (it != r.before.end()) out = it->second;
    return it != r.before.end();
  };
  std::vector<SnapshotPtr> archive_snap(archive_.size()), history_snap(history_.size());
  size_t a = 0, h = 0;  // the first archived / windowed input that is not the job's own
  for (; a < archive_.size() && own(archive_[a].key); ++a)
    if (archive_[a].checkpoint && archive_[a].key != r.base_key && !lookup(archive_[a].key, archive_snap[a]))
      return std::nullopt;
  if (a == archive_.size())
    for (; h < history_.size() && own(history_[h].key); ++h)
      if (!lookup(history_[h].key, history_snap[h])) return std::nullopt;
  // The state before that input: the job's before its next own input (an inserted input), or its final state.
  SnapshotPtr resume;
  if (a < archive_.size() || h < history_.size()) {
    const InputOrder k = a < archive_.size() ? archive_[a].key : history_[h].key;
    const auto next = std::lower_bound(r.keys.begin(), r.keys.end(), k);
    if (next != r.keys.end() && !lookup(*next, resume)) return std::nullopt;
  }
  for (size_t i = 0; i < a; ++i)
    if (archive_snap[i]) archive_[i].checkpoint = std::move(archive_snap[i]);
  for (size_t i = 0; i < h; ++i) history_[i].before = std::move(history_snap[i]);
  cur_ = resume ? resume->copy() : std::move(r.state);
  int64_t n = 0;
  for (size_t i = a; i < archive_.size(); ++i, ++n) {
    if (archive_[i].checkpoint && archive_[i].key != r.base_key)
      archive_[i].checkpoint = std::make_shared<const Snapshot>(cur_.copy());
    process(archive_[i].input, false);
  }
  for (size_t i = h; i < history_.size(); ++i, ++n) {
    history_[i].before = std::make_shared<const Snapshot>(cur_.copy());
    process(history_[i].input, false);
  }
  return n;
}

void EstimatorNode::logRerun(const RerunResult& r, const std::string& how) const {
  spdlog::info("estimator: re-run from t={} over {} inputs ({:.1f} s of data), anchors [{}] uncertain from there "
               "(σ {} m around their calibration): {:.1f} ms wall{}",
               formatSeconds(r.t0), r.keys.size(), (r.t_end - r.t0).sec(), r.ids, options_.refine.rerun_prior_sigma_m,
               r.wall_ms, how);
}

}  // namespace meshnav::estimator
