/// @file estimator_node_reentry.cpp
/// @brief EstimatorNode: the release of the tag ranges held after an aiding gap (ReentryGate,
/// estimator/uwb/reentry_gate.h): the node rewinds to the first held range and re-processes the
/// history, fusing the agreeing ranges at their own times (the out-of-sequence machinery).

#include <algorithm>

#include "estimator/node/estimator_node.h"

namespace meshnav::estimator {

void EstimatorNode::releaseReentryIfDue() {
  const std::optional<InputOrder> first_key = reentry_.releaseIfDue(*timeline_.newest());
  if (!first_key) return;
  const auto it = timeline_.find(*first_key);
  if (it == timeline_.window().end()) {
    diag_.count("range_reentry_lost");  // cannot happen with reentry_hold_s <= window_s; counted if it does
  } else {
    cur_ = it->before->copy();
    next_imu_ = nextImuInWindow(it);
    process(it->input, false);
    replayAfter(it);  // resets next_imu_
  }
  // Fates are needed while a rewind or a re-run may replay their range; rejected ones as long as a re-run.
  const double keep_s = std::max(options_.window_s, rerun_.enabled() ? options_.refine.max_history_s : 0.0);
  reentry_.forgetFates(*timeline_.newest(), options_.window_s, keep_s);
}

}  // namespace meshnav::estimator
