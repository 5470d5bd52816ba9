/// @file estimator_node_checkpoint.cpp
/// @brief EstimatorNode: the restart checkpoint it writes (estimator/restart/resume.h).

#include <stdexcept>

#include "estimator/node/estimator_node.h"

namespace meshnav::estimator {

EstimatorCheckpoint EstimatorNode::checkpoint() const {
  if (!initialized()) throw std::logic_error("EstimatorNode::checkpoint: not initialized");
  return makeCheckpoint(*cur_.filter, *cur_.network, cur_.landed, sensors_.baro.reference(), options_);
}

}  // namespace meshnav::estimator
