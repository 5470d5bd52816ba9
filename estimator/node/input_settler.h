#pragma once
/// @file input_settler.h
/// @brief Before the filter's initialization: inputs released to the initializers in the
/// canonical order (estimator_input.h) once nothing earlier can still arrive, so that the first
/// alignment sees the same data whether the inputs came in one process, in time order, or over
/// LCM from separate bridges, where a range stamped before an IMU sample may arrive after it.
///
/// The model: each measurement stream (IMU, RANGE, BARO, HEIGHT) arrives in its own time order
/// (one sender per stream, FIFO on loopback), so once every stream has delivered an input stamped
/// after t, every input stamped before t has arrived. The watermark is
///   W = min over the streams of their newest stamp,
/// over the streams seen so far and the two every UWB-aided INS has (IMU and RANGE) even before
/// their first input,
/// and the inputs stamped before W are settled. A stream that stops (an outage, the end of its
/// recording) would hold W back: inputs older than the newest stamp minus `max_hold_s` are
/// settled anyway. In one process the inputs come in the canonical order already, so the
/// released sequence is the arrival sequence and nothing changes (tested); over LCM only an input
/// later than both bounds arrives out of order ("late_for_initialization" in the node).
/// Flight states and a fleet's peer ranges do not move W; they are held and released in order.
/// ANCHOR_INIT and commands are not given to the settler: the node applies them at once (a
/// command stamped far ahead must not move the clock, EstimatorTimeGuard).
/// While a restart's checkpoint is offered (until the first IMU sample decides whether it resumes
/// the pose, EstimatorNode::resumeFrom) the node does not hold inputs: a resumed pose comes at once.

#include <map>
#include <optional>
#include <vector>

#include "estimator/node/estimator_input.h"

namespace meshnav::estimator {

class InputSettler {
 public:
  /// `max_hold_s`: init.settle_max_s, how far behind the newest stamp an input is settled even
  /// while a stream has not passed it [s].
  /// `expect_ranges`: the setup has tags, so a RANGE stream will come: until its first input the
  /// watermark waits for it too (else the IMU samples before the first range would go ahead of it).
  explicit InputSettler(double max_hold_s, bool expect_ranges = true)
      : max_hold_s_(max_hold_s), expect_ranges_(expect_ranges) {}

  /// Holds `in`. Returns false when it comes after an input stamped later than it was released:
  /// it is not held (the caller processes it at once, out of order).
  bool add(const EstimatorInput& in);
  /// The settled inputs, in the canonical order, taken out of the settler.
  std::vector<EstimatorInput> takeSettled();
  /// Every held input, in the canonical order (the filter was initialized, the stream ended).
  std::vector<EstimatorInput> takeAll();
  /// An input of a stream the watermark waits for (IMU, RANGE, BARO, HEIGHT).
  static bool isStreamInput(const EstimatorInput& in);
  /// The watermark W, once every stream expected (IMU, and RANGE unless told otherwise) has come.
  std::optional<Timestamp> watermark() const;
  size_t size() const { return held_.size(); }
  /// Forgets everything (a node reset).
  void clear();

 private:
  double max_hold_s_;
  bool expect_ranges_;
  std::multimap<InputOrder, EstimatorInput> held_;  ///< equal keys keep their arrival order
  std::map<int, Timestamp> newest_by_kind_;         ///< measurement streams: kind rank → newest stamp
  std::optional<Timestamp> newest_;
  std::optional<InputOrder> released_;              ///< the last input released
};

}  // namespace meshnav::estimator
