#pragma once
/// @file joint_set_bound.h
/// @brief The bound on a DAH joint set's anchors (issue 10, `uwb.dah_joint_max_anchors`;
/// docs/modular_estimator.md, "Joint sets"). A set that holds the IMU is stacked by every update,
/// so its size is the cost of DAH's update; without a bound every anchor calibrated on a long
/// flight joins it.

#include "common/types.h"
#include "estimator/filter/fusion_strategy.h"

namespace meshnav::estimator {

/// After `joined` (an estimated anchor) joined its set: while the set holds more than
/// `max_anchors` estimated anchors (AnchorKind), the other anchor with the smallest trace of its
/// position covariance (the most refined; ties: the smaller id) leaves it
/// (FusionStrategy::leaveJointSet); `joined` itself stays. `max_anchors` ≤ 0: no bound. Returns
/// the number of anchors that left.
int boundJointSetAnchors(FusionStrategy& f, SensorId joined, int max_anchors);

}  // namespace meshnav::estimator
