/// @file estimator_node_rerun_async.cpp
/// @brief EstimatorNode, the re-run on an anchor join off the publishing path (`refine.rerun_mode`
/// async, docs/modular_estimator.md "Re-run on anchor join"): a worker thread computes the re-run
/// on a replay node of its own from the job's immutable copies while the node keeps processing and
/// publishing; at the first input after the worker is done the node swaps the result in and
/// re-processes, from the re-run's state, the stored inputs that came (or were inserted) meanwhile.
/// A join while a re-run runs is queued: one more re-run, with every joined anchor, after the swap.

#include <spdlog/spdlog.h>

#include "estimator/node/estimator_node_rerun.h"

namespace meshnav::estimator {

EstimatorNode::~EstimatorNode() { abandonRerun(); }

void EstimatorNode::copyReplayContext(const EstimatorNode& live) {
  init_.copyStillnessFrom(live.init_);
  baro_.setReference(live.baro_.reference());
  height_ = live.height_;
  rerun_anchors_ = live.rerun_anchors_;
  gravity_.takeSignOf(live.gravity_);
  recovery_.copyGapWindowFrom(live.recovery_);
  zupt_model_ = live.zupt_model_;
  // Ranges after a gap: rejected ones stay out of the re-run, held ones wait for the live node's release.
  reentry_.copyFatesFrom(live.reentry_);
}

void EstimatorNode::launchRerun(RerunJob job, std::chrono::steady_clock::time_point t_job) {
  ScopedStepTimer timer(timings_, "rerun_start");  // the worker's node, on the node's thread
  // options_ already hold the setup's figures; applying them again changes nothing.
  std::unique_ptr<EstimatorNode> replay(new EstimatorNode(options_, setup_, {}, Quiet{}));
  replay->copyReplayContext(*this);
  auto run = std::make_unique<RunningRerun>();
  run->end_key = job.keys.back();
  run->started = std::chrono::steady_clock::now();
  run->result = std::async(std::launch::async, [replay = std::move(replay), job = std::move(job), cancel = run->cancel,
                                                hook = rerun_worker_hook_]() mutable {
    if (hook) hook();
    return replay->computeRerun(std::move(job), *cancel);
  });
  run->start_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_job).count();
  rerun_ = std::move(run);
}

void EstimatorNode::pollRerun(bool wait) {
  if (!rerun_ || (!wait && rerun_->result.wait_for(std::chrono::seconds(0)) != std::future_status::ready)) return;
  const std::unique_ptr<RunningRerun> run = std::move(rerun_);
  RerunResult r = run->result.get();
  const auto swap0 = std::chrono::steady_clock::now();
  ScopedStepTimer timer(timings_, "rerun_swap");
  const std::optional<int64_t> replayed = applyRerun(r, run->divergence);
  if (!replayed) {  // a stored input the re-run has no snapshot for (not expected): run it again
    diag_.report("rerun_swap_failed", "estimator: the re-run's snapshots do not fit the stored inputs; re-run queued");
    rerun_pending_ = true;
    return;
  }
  diag_.count("rerun_replayed", *replayed);
  const auto ms = [](auto d) { return std::chrono::duration<double, std::milli>(d).count(); };
  const auto now = std::chrono::steady_clock::now();
  // What blocked the node: taking the copies and starting the worker, and the swap.
  logRerun(r, fmt::format(" on a worker (started in {:.1f} ms); swapped in {:.1f} ms after its start, re-processing "
                          "the {} inputs stored meanwhile{} in {:.1f} ms",
                          run->start_ms, ms(now - run->started), *replayed,
                          run->divergence ? " (some inserted among its own)" : "", ms(now - swap0)));
}

void EstimatorNode::abandonRerun() {
  if (!rerun_) return;
  rerun_->cancel->store(true, std::memory_order_relaxed);
  rerun_->result.wait();
  rerun_.reset();
  diag_.count("rerun_abandoned");
}

void EstimatorNode::finishRerun() {
  while (rerun_) {
    pollRerun(true);
    if (rerun_pending_ && initialized()) startRerun();  // the re-run queued behind it
  }
}

}  // namespace meshnav::estimator
