/// @file estimator_node_time.cpp
/// @brief EstimatorNode after the time guard moved its clock backwards (InputGate::kClockBack,
/// common/time_guard.h): everything the node holds is stamped ahead of the data, so nothing could
/// ever be processed; it starts over.
#include <spdlog/spdlog.h>

#include "estimator/node/estimator_node.h"

namespace meshnav::estimator {

void EstimatorNode::startOverAfterClockBack() {
  spdlog::warn("estimator: the clock was ahead of every input; the node starts over");
  resetAll();
  timeline_.forgetNewest();
  outputs_.resetAll();
  recovery_.resetAll();
  init_.forgetStreams();
}

}  // namespace meshnav::estimator
