/// @file estimator_node_checkpoint.cpp
/// @brief EstimatorNode: the restart checkpoint it writes (estimator/restart/resume.h).

#include <stdexcept>

#include "estimator/node/estimator_node.h"

namespace meshnav::estimator {

EstimatorCheckpoint EstimatorNode::checkpoint(bool with_anchors) const {
  if (!initialized()) throw std::logic_error("EstimatorNode::checkpoint: not initialized");
  return makeCheckpoint(*cur_.filter, *cur_.network, cur_.landed, sensors_.baro.reference(), options_, with_anchors);
}

std::set<SensorId> EstimatorNode::estimatedAnchorIds() const {
  std::set<SensorId> ids;
  if (!cur_.filter) return ids;
  for (const auto& [id, anchor] : cur_.filter->state().values<AnchorKind>()) ids.insert(id);
  return ids;
}

}  // namespace meshnav::estimator
