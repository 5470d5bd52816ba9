#pragma once
/// @file anchor_rerun.h
/// @brief AnchorRerun: the second pass on an anchor join (RefineOptions, docs/modular_estimator.md
/// "Re-run on anchor join", docs/decisions/003-rerun-on-anchor-join.md).
///
/// The calibration of a dropped anchor used the filter's trajectory, so refining the calibrated
/// belief forward cannot undo that trajectory's error; estimating the anchor jointly with the
/// trajectory from the start can. On a live ANCHOR_INIT (`noteJoin`) a re-run is due after the next
/// input that is not an ANCHOR_INIT (anchors calibrated together share one). It restores the oldest
/// stored context (InputTimeline), adds every joined anchor there with a loose prior
/// (`loosePrior`: the calibration's mean, σ `refine.rerun_prior_sigma_m` per axis, γ σ
/// `refine.rerun_gamma_sigma_m`) and re-processes every stored input, refreshing their contexts.
///
/// - `sync`: computed inline on the live node (deterministic: replays, tests, paper tables).
/// - `async`: a job of immutable copies (the base context, the priors, the stored inputs) runs on a
///   worker with a replay node of its own while the live node keeps processing and publishing; at
///   the first input after it is done (`poll`) its result is swapped in, and the inputs stored or
///   inserted meanwhile are re-processed from it. A join while a re-run runs queues one more.
/// Counted: "rerun", "rerun_inputs", "rerun_skipped" (nothing stored), "rerun_queued",
/// "rerun_replayed", "rerun_abandoned" (a re-initialization or the end), "rerun_swap_failed".

#include <atomic>
#include <chrono>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "common/messages.h"
#include "estimator/core/estimator_options.h"
#include "estimator/node/input_timeline.h"
#include "estimator/node/step_timings.h"
#include "estimator/refine/rerun_replayer.h"

namespace meshnav::estimator {

/// Immutable copies taken on the node's thread.
struct RerunJob {
  std::shared_ptr<const FilterContext> base;  ///< the context before the oldest stored input
  InputOrder base_key;                        ///< that input: its checkpoint stays the base (no re-run anchors)
  std::vector<AnchorInit> priors;             ///< the joined anchors with the loose prior, at the base's time
  std::vector<InputOrder> keys;               ///< the stored inputs in processing order
  std::vector<EstimatorInput> inputs;
  std::vector<char> keep_before;              ///< 1: the context before this input is returned
};

struct RerunResult {
  FilterContext state;  ///< after the last input
  std::map<InputOrder, std::shared_ptr<const FilterContext>> before;
  std::vector<InputOrder> keys;  ///< the job's inputs (sorted)
  InputOrder base_key;
  Timestamp t0;                  ///< the base's time
  Timestamp t_end;               ///< the time after its last input
  std::string ids;               ///< anchors added with the loose prior
  double wall_ms = 0.0;          ///< computing time
  bool cancelled = false;
};

class AnchorRerun {
 public:
  AnchorRerun(const EstimatorOptions& options, Diagnostics& diag, StepTimings& timings);
  ~AnchorRerun();
  AnchorRerun(const AnchorRerun&) = delete;
  AnchorRerun& operator=(const AnchorRerun&) = delete;

  /// `refine.rerun_on_anchor_join` for this strategy (dah: and `refine.rerun_with_dah`).
  static bool enabledBy(const EstimatorOptions& options);
  bool enabled() const { return enabled_; }
  /// A worker re-run has not been swapped in yet.
  bool running() const { return running_ != nullptr; }
  /// A join waits for its re-run.
  bool pending() const { return pending_; }
  /// Joined anchors forgotten and nothing pending (a reset).
  void reset();
  /// The replay node's copy of the joined anchors.
  void copyJoinedFrom(const AnchorRerun& live) { joined_ = live.joined_; }
  /// An anchor removed by command takes no part in later re-runs.
  void forget(SensorId id);
  /// While anchors held before the initialization (or from a checkpoint) are applied: they keep
  /// their own covariance and start no re-run.
  void setApplyingHeld(bool on) { applying_held_ = on; }
  /// True when an ANCHOR_INIT replayed by a re-run or rewind must be skipped: its anchor is already
  /// in the state as a re-run's uncertain anchor.
  bool skipReplayed(const AnchorInit& a, bool first, const FusionStrategy& f) const;
  /// A live ANCHOR_INIT the filter took: remembered, a re-run due after the next other input.
  void noteJoin(const AnchorInit& a, bool first, const FusionStrategy& f);
  /// The ANCHOR_INIT of a re-run: the calibration's means, position σ and γ σ of RefineOptions.
  AnchorInit loosePrior(const AnchorInit& a, Timestamp t) const;

  /// Starts the pending re-run: inline on `live`, or (async) on a worker with the node `makeReplay`
  /// returns. Nothing stored: counted "rerun_skipped".
  void start(InputTimeline& timeline, RerunReplayer& live,
             const std::function<std::unique_ptr<RerunReplayer>()>& makeReplay);
  /// Swaps a finished worker re-run in (`wait`: blocks until it is finished).
  void poll(bool wait, InputTimeline& timeline, RerunReplayer& live);
  /// Drops a running worker re-run, counted "rerun_abandoned".
  void abandon();
  /// An input inserted among the stored ones while a worker runs: its snapshots do not hold from it on.
  void noteInserted(const InputOrder& k);
  /// Called on the worker before it starts (EstimatorNodeTesting).
  void setWorkerHook(std::function<void()> hook) { worker_hook_ = std::move(hook); }

  /// Immutable copies of what a re-run needs (nullopt: nothing stored).
  std::optional<RerunJob> makeJob(const InputTimeline& timeline) const;
  /// Runs `job` on `replayer`'s context.
  static RerunResult compute(RerunJob job, RerunReplayer& replayer, const std::atomic<bool>& cancel);
  /// Takes a result: its snapshots for the stored inputs it processed, the state before the first
  /// it did not (`divergence`: the oldest input inserted among its inputs while it ran), and
  /// re-processes from there. The number re-processed; nullopt when a snapshot is missing.
  static std::optional<int64_t> apply(RerunResult& r, std::optional<InputOrder> divergence, InputTimeline& timeline,
                                      RerunReplayer& live);

 private:
  struct Running;
  void log(const RerunResult& r, const std::string& how) const;

  RefineOptions refine_;
  Diagnostics& diag_;
  StepTimings& timings_;
  bool enabled_ = false;
  bool async_ = false;
  bool pending_ = false;
  bool applying_held_ = false;
  std::vector<AnchorInit> joined_;  ///< calibrated anchors joined live, by order of joining
  std::unique_ptr<Running> running_;
  std::function<void()> worker_hook_;
};

}  // namespace meshnav::estimator
