/// @file estimator_node_rerun.cpp
/// @brief EstimatorNode's side of the re-run on an anchor join (AnchorRerun,
/// estimator/refine/anchor_rerun.h): starting it, the replay node of a worker re-run, the anchors
/// held before the initialization, and the end of a replay or of the process.

#include "estimator/node/estimator_node.h"

namespace meshnav::estimator {

EstimatorNode::~EstimatorNode() { rerun_.abandon(); }

void EstimatorNode::startRerun() {
  rerun_.start(timeline_, *this, [this] { return makeReplayNode(); });
}

std::unique_ptr<RerunReplayer> EstimatorNode::makeReplayNode() const {
  // options_ already hold the setup's figures; applying them again changes nothing.
  std::unique_ptr<EstimatorNode> replay(new EstimatorNode(options_, setup_, {}, Quiet{}));
  replay->init_.copyStillnessFrom(init_);
  replay->sensors_.baro.setReference(sensors_.baro.reference());
  replay->sensors_.height = sensors_.height;
  replay->rerun_.copyJoinedFrom(rerun_);
  replay->gravity_.takeSignOf(gravity_);
  replay->recovery_.copyGapWindowFrom(recovery_);
  replay->sensors_.zupt = sensors_.zupt;
  // Ranges after a gap: rejected ones stay out of the re-run, held ones wait for the live node's release.
  replay->reentry_.copyFatesFrom(reentry_);
  // The base is private (only the node and AnchorRerun see the node as a replayer): convert here.
  return std::unique_ptr<RerunReplayer>(static_cast<RerunReplayer*>(replay.release()));
}

void EstimatorNode::applyHeldAnchors(Timestamp t) {
  const std::vector<AnchorInit> held = sensors_.anchor_join.takeHeld();
  rerun_.setApplyingHeld(true);  // resumed or early anchors keep their covariance (no re-run)
  for (auto a : held) {
    a.t = t;
    onInput(a);
  }
  rerun_.setApplyingHeld(false);
}

void EstimatorNode::finishRerun() {
  while (rerun_.running()) {
    rerun_.poll(true, timeline_, *this);
    if (rerun_.pending() && initialized()) startRerun();  // the re-run queued behind it
  }
}

}  // namespace meshnav::estimator
