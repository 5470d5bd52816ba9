/// @file anchor_rerun.cpp
/// @brief AnchorRerun: the job, its computation on a replayer, the swap and the worker.
#include "estimator/refine/anchor_rerun.h"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace meshnav::estimator {

/// A worker re-run: its future result and what the node learns while it runs.
struct AnchorRerun::Running {
  std::future<RerunResult> result;
  std::shared_ptr<std::atomic<bool>> cancel = std::make_shared<std::atomic<bool>>(false);
  InputOrder end_key;                    ///< the job's newest input
  std::optional<InputOrder> divergence;  ///< oldest input inserted at or before end_key meanwhile
  std::chrono::steady_clock::time_point started;
  double start_ms = 0.0;  ///< the node's thread taking the copies and starting the worker
};

AnchorRerun::AnchorRerun(const EstimatorOptions& options, Diagnostics& diag, StepTimings& timings)
    : refine_(options.refine),
      diag_(diag),
      timings_(timings),
      enabled_(enabledBy(options)),
      async_(options.refine.rerun_mode == "async") {}

AnchorRerun::~AnchorRerun() { abandon(); }

bool AnchorRerun::enabledBy(const EstimatorOptions& options) {
  return options.refine.rerun_on_anchor_join && (options.strategy != "dah" || options.refine.rerun_with_dah);
}

void AnchorRerun::reset() {
  joined_.clear();
  pending_ = false;
}

void AnchorRerun::forget(SensorId id) {
  std::erase_if(joined_, [&](const AnchorInit& a) { return a.id == id; });
}

bool AnchorRerun::skipReplayed(const AnchorInit& a, bool first, const FusionStrategy& f) const {
  if (first || !enabled_ || !f.state().values<AnchorKind>().count(a.id)) return false;
  return std::any_of(joined_.begin(), joined_.end(), [&](const AnchorInit& r) { return r.id == a.id; });
}

void AnchorRerun::noteJoin(const AnchorInit& a, bool first, const FusionStrategy& f) {
  if (!first || !enabled_ || applying_held_ || !f.state().values<AnchorKind>().count(a.id)) return;
  forget(a.id);
  joined_.push_back(a);
  pending_ = true;
  if (running_) diag_.count("rerun_queued");  // runs after the current one, with every joined anchor
}

AnchorInit AnchorRerun::loosePrior(const AnchorInit& a, Timestamp t) const {
  AnchorInit l = a;
  l.t = t;
  l.cov_p_m2 = Eigen::Matrix3d::Identity() * refine_.rerun_prior_sigma_m * refine_.rerun_prior_sigma_m;
  l.cov_gamma_p_m2.resize(0, 0);
  l.cov_gamma_m2.resize(0, 0);
  for (PairBias& b : l.biases)
    if (b.sigma_gamma_m > 0.0) {
      b.sigma_gamma_m = refine_.rerun_gamma_sigma_m;
      if (!refine_.rerun_gamma_from_calibration) b.gamma_m = 0.0;
    }
  return l;
}

void AnchorRerun::start(InputTimeline& timeline, RerunReplayer& live,
                        const std::function<std::unique_ptr<RerunReplayer>()>& makeReplay) {
  pending_ = false;
  const auto t_job = std::chrono::steady_clock::now();
  std::optional<RerunJob> job = makeJob(timeline);
  if (!job) {
    diag_.count("rerun_skipped");  // nothing stored (e.g. right after a re-initialization)
    return;
  }
  diag_.count("rerun");
  diag_.count("rerun_inputs", static_cast<int64_t>(job->inputs.size()));
  if (!async_) {
    ScopedStepTimer timer(timings_, "rerun");
    const std::atomic<bool> never{false};
    RerunResult r = compute(std::move(*job), live, never);
    apply(r, std::nullopt, timeline, live);  // inline: every stored input is the job's own, nothing to re-process
    log(r, "");
    return;
  }
  ScopedStepTimer timer(timings_, "rerun_start");  // the worker's node, on the node's thread
  std::unique_ptr<RerunReplayer> replay = makeReplay();
  auto run = std::make_unique<Running>();
  run->end_key = job->keys.back();
  run->started = std::chrono::steady_clock::now();
  run->result = std::async(std::launch::async, [replay = std::move(replay), job = std::move(*job), cancel = run->cancel,
                                                hook = worker_hook_]() mutable {
    if (hook) hook();
    return compute(std::move(job), *replay, *cancel);
  });
  run->start_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_job).count();
  running_ = std::move(run);
}

std::optional<RerunJob> AnchorRerun::makeJob(const InputTimeline& timeline) const {
  const auto& archive = timeline.archive();
  const auto& window = timeline.window();
  const bool from_archive = !archive.empty();
  RerunJob job;
  job.base = from_archive ? archive.front().checkpoint : window.empty() ? nullptr : window.front().before;
  if (!job.base || !job.base->filter) return std::nullopt;
  job.base_key = from_archive ? archive.front().key : window.front().key;
  const Timestamp t0 = job.base->filter->state().t;
  for (const AnchorInit& a : joined_) job.priors.push_back(loosePrior(a, t0));
  const size_t n = archive.size() + window.size();
  job.keys.reserve(n);
  job.inputs.reserve(n);
  job.keep_before.reserve(n);
  for (const auto& a : archive) {
    job.keys.push_back(a.key);
    job.inputs.push_back(a.input);
    job.keep_before.push_back(a.checkpoint && a.key != job.base_key);  // the base stays the state without them
  }
  for (const auto& e : window) {  // the out-of-sequence window: a later rewind must restore re-run states
    job.keys.push_back(e.key);
    job.inputs.push_back(e.input);
    job.keep_before.push_back(1);
  }
  return job;
}

RerunResult AnchorRerun::compute(RerunJob job, RerunReplayer& replayer, const std::atomic<bool>& cancel) {
  const auto wall0 = std::chrono::steady_clock::now();
  RerunResult r;
  r.base_key = job.base_key;
  FilterContext& cur = replayer.replayContext();
  cur = job.base->copy();
  r.t0 = cur.filter->state().t;
  for (const AnchorInit& a : job.priors) {
    if (cur.filter->state().values<AnchorKind>().count(a.id)) continue;  // from an earlier re-run's checkpoint
    replayer.replayAnchor(a);
    r.ids += (r.ids.empty() ? "" : ", ") + std::to_string(a.id);
  }
  const std::optional<double> span_s = replayer.nextImuSpan_s();
  for (size_t i = 0; i < job.inputs.size(); ++i) {
    if (cancel.load(std::memory_order_relaxed)) {
      r.cancelled = true;
      break;
    }
    if (job.keep_before[i]) r.before.emplace(job.keys[i], std::make_shared<const FilterContext>(cur.copy()));
    replayer.replay(job.inputs[i], span_s ? nextImuSample(i, job.inputs.size(), [&](size_t j) -> const EstimatorInput& {
      return job.inputs[j];
    }, *span_s) : std::nullopt);
  }
  r.t_end = cur.filter->state().t;
  r.state = std::move(cur);
  r.keys = std::move(job.keys);
  r.wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall0).count();
  return r;
}

std::optional<int64_t> AnchorRerun::apply(RerunResult& r, std::optional<InputOrder> divergence, InputTimeline& timeline,
                                          RerunReplayer& live) {
  using ContextPtr = std::shared_ptr<const FilterContext>;
  auto& archive = timeline.archive();
  auto& window = timeline.window();
  // The job's own stored inputs: up to its newest, before any input inserted among them meanwhile.
  auto own = [&](const InputOrder& k) { return !r.keys.empty() && k <= r.keys.back() && (!divergence || k < *divergence); };
  auto lookup = [&](const InputOrder& k, ContextPtr& out) {
    const auto it = r.before.find(k);
    if (it != r.before.end()) out = it->second;
    return it != r.before.end();
  };
  std::vector<ContextPtr> archive_snap(archive.size()), window_snap(window.size());
  size_t a = 0, h = 0;  // the first archived / windowed input that is not the job's own
  for (; a < archive.size() && own(archive[a].key); ++a)
    if (archive[a].checkpoint && archive[a].key != r.base_key && !lookup(archive[a].key, archive_snap[a]))
      return std::nullopt;
  if (a == archive.size())
    for (; h < window.size() && own(window[h].key); ++h)
      if (!lookup(window[h].key, window_snap[h])) return std::nullopt;
  // The state before that input: the job's before its next own input (an inserted input), or its final state.
  ContextPtr resume;
  if (a < archive.size() || h < window.size()) {
    const InputOrder k = a < archive.size() ? archive[a].key : window[h].key;
    const auto next = std::lower_bound(r.keys.begin(), r.keys.end(), k);
    if (next != r.keys.end() && !lookup(*next, resume)) return std::nullopt;
  }
  for (size_t i = 0; i < a; ++i)
    if (archive_snap[i]) archive[i].checkpoint = std::move(archive_snap[i]);
  for (size_t i = 0; i < h; ++i) window[i].before = std::move(window_snap[i]);
  FilterContext& cur = live.replayContext();
  cur = resume ? resume->copy() : std::move(r.state);
  // The stored inputs as one sequence (archive, then window): a measurement's next IMU sample may be
  // the window's first.
  const size_t na = archive.size(), n_all = na + window.size();
  auto at = [&](size_t j) -> const EstimatorInput& { return j < na ? archive[j].input : window[j - na].input; };
  const std::optional<double> span_s = live.nextImuSpan_s();
  auto next = [&](size_t j) { return span_s ? nextImuSample(j, n_all, at, *span_s) : std::nullopt; };
  int64_t n = 0;
  for (size_t i = a; i < na; ++i, ++n) {
    if (archive[i].checkpoint && archive[i].key != r.base_key)
      archive[i].checkpoint = std::make_shared<const FilterContext>(cur.copy());
    live.replay(archive[i].input, next(i));
  }
  for (size_t i = h; i < window.size(); ++i, ++n) {
    window[i].before = std::make_shared<const FilterContext>(cur.copy());
    live.replay(window[i].input, next(na + i));
  }
  return n;
}

void AnchorRerun::poll(bool wait, InputTimeline& timeline, RerunReplayer& live) {
  if (!running_ || (!wait && running_->result.wait_for(std::chrono::seconds(0)) != std::future_status::ready)) return;
  const std::unique_ptr<Running> run = std::move(running_);
  RerunResult r = run->result.get();
  const auto swap0 = std::chrono::steady_clock::now();
  ScopedStepTimer timer(timings_, "rerun_swap");
  const std::optional<int64_t> replayed = apply(r, run->divergence, timeline, live);
  if (!replayed) {  // a stored input the re-run has no snapshot for (not expected): run it again
    diag_.report("rerun_swap_failed", "estimator: the re-run's snapshots do not fit the stored inputs; re-run queued");
    pending_ = true;
    return;
  }
  diag_.count("rerun_replayed", *replayed);
  const auto ms = [](auto d) { return std::chrono::duration<double, std::milli>(d).count(); };
  const auto now = std::chrono::steady_clock::now();
  // What blocked the node: taking the copies and starting the worker, and the swap.
  log(r, fmt::format(" on a worker (started in {:.1f} ms); swapped in {:.1f} ms after its start, re-processing "
                     "the {} inputs stored meanwhile{} in {:.1f} ms",
                     run->start_ms, ms(now - run->started), *replayed,
                     run->divergence ? " (some inserted among its own)" : "", ms(now - swap0)));
}

void AnchorRerun::abandon() {
  if (!running_) return;
  running_->cancel->store(true, std::memory_order_relaxed);
  running_->result.wait();
  running_.reset();
  diag_.count("rerun_abandoned");
}

void AnchorRerun::noteInserted(const InputOrder& k) {
  if (running_ && k <= running_->end_key && (!running_->divergence || k < *running_->divergence))
    running_->divergence = k;
}

void AnchorRerun::log(const RerunResult& r, const std::string& how) const {
  spdlog::info("estimator: re-run from t={} over {} inputs ({:.1f} s of data), anchors [{}] uncertain from there "
               "(σ {} m around their calibration): {:.1f} ms wall{}",
               formatSeconds(r.t0), r.keys.size(), (r.t_end - r.t0).sec(), r.ids, refine_.rerun_prior_sigma_m,
               r.wall_ms, how);
}

}  // namespace meshnav::estimator
