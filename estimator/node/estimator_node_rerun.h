#pragma once
/// @file estimator_node_rerun.h
/// @brief EstimatorNode's re-run on an anchor join as a job (docs/modular_estimator.md, "Re-run on
/// anchor join"): what it starts from, what it returns and the worker that computes it. Internal
/// to the node (estimator_node_rerun.cpp, estimator_node_rerun_async.cpp).
///
/// A job holds immutable copies taken on the node's thread: the base snapshot (shared, never
/// modified: the filter's instances are copy-on-write), the loose priors and every stored input
/// (archive_ then history_) with its key. It runs on a node of its own (the live one inline, a
/// replay node on the worker) and returns the state after its last input plus the snapshots before
/// the inputs whose stored snapshot it refreshes (archive checkpoints after the first, the window).

#include <chrono>
#include <future>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "estimator/node/estimator_node.h"

namespace meshnav::estimator {

struct EstimatorNode::RerunJob {
  std::shared_ptr<const Snapshot> base;  ///< the state before the oldest stored input
  InputOrder base_key;                   ///< that input: its checkpoint stays the base (no re-run anchors)
  std::vector<AnchorInit> priors;        ///< the joined anchors with the loose prior, at the base's time
  std::vector<InputOrder> keys;          ///< the stored inputs in processing order
  std::vector<EstimatorInput> inputs;
  std::vector<char> keep_before;         ///< 1: the snapshot before this input is returned
};

struct EstimatorNode::RerunResult {
  Snapshot state;  ///< after the last input
  std::map<InputOrder, std::shared_ptr<const Snapshot>> before;
  std::vector<InputOrder> keys;  ///< the job's inputs (sorted)
  InputOrder base_key;
  Timestamp t0;                  ///< the base's time
  Timestamp t_end;               ///< the time after its last input
  std::string ids;               ///< anchors added with the loose prior
  double wall_ms = 0.0;          ///< computing time
  bool cancelled = false;
};

/// A worker re-run: its future result and what the node learns while it runs.
struct EstimatorNode::RunningRerun {
  std::future<RerunResult> result;
  std::shared_ptr<std::atomic<bool>> cancel = std::make_shared<std::atomic<bool>>(false);
  InputOrder end_key;                    ///< the job's newest input
  std::optional<InputOrder> divergence;  ///< oldest input inserted at or before end_key meanwhile
  std::chrono::steady_clock::time_point started;
  double start_ms = 0.0;  ///< the node's thread taking the copies and starting the worker
  /// An input inserted into the stored ones: from it on the re-run's snapshots do not hold.
  void noteInserted(const InputOrder& k) {
    if (k <= end_key && (!divergence || k < *divergence)) divergence = k;
  }
};

}  // namespace meshnav::estimator
