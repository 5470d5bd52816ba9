#pragma once
/// @file rerun_replayer.h
/// @brief What a re-run (AnchorRerun) needs of the node that re-processes its inputs: the live node
/// for a re-run inline, a replay node of its own on the worker. Only the node implements it.

#include <optional>

#include "common/messages.h"
#include "estimator/node/estimator_input.h"
#include "estimator/node/filter_context.h"

namespace meshnav::estimator {

class RerunReplayer {
 public:
  virtual ~RerunReplayer() = default;
  /// The context inputs are processed on.
  virtual FilterContext& replayContext() = 0;
  /// Processes a stored input again (not counted, nothing published); `next_imu`: the IMU sample
  /// after it when it is a measurement (nextImuSample), which its propagation interpolates towards.
  virtual void replay(const EstimatorInput& in, const std::optional<ImuSample>& next_imu) = 0;
  /// How far after a measurement its next IMU sample is looked for (`imu.max_dt_s`) [s]; nullopt
  /// when measurements are not propagated towards it (`imu.hold_for_next_sample` off).
  virtual std::optional<double> nextImuSpan_s() const = 0;
  /// Adds a calibrated anchor with its loose prior at the re-run's start.
  virtual void replayAnchor(const AnchorInit& a) = 0;
};

}  // namespace meshnav::estimator
