#pragma once
/// @file input_gate.h
/// @brief Admission of every input before it reaches the estimator's history or filter: values
/// (finite, plausible, valid ids), the time guard (common/time_guard.h) and duplicates.
///
/// Three checks in the order the node applies them (EstimatorNode::onInput):
/// 1. `valid`: a non-finite or absurd value is refused and counted "bad_input" with the channel
///    and time ("RANGE t=12.300000: bad range ...").
/// 2. `admitTime`: a measurement stamped farther than `time.max_offset_s` from the current time is
///    refused and counted per kind ("IMU:time_ahead", "RANGE:time_behind"); a jump of the whole
///    stream moves the clock after `time.rebase_after` agreeing inputs ("time_rebased"). A jump
///    backwards is `Verdict::kClockBack`: everything the node holds is stamped ahead of the data and
///    the node must start over. Commands (ANCHOR_INIT, ESTIMATOR_CMD) do not drive the clock: far
///    from it they are restamped to the current time ("<KIND>:time_clamped").
/// 3. `admitOnce`: an input that comes a second time (same kind, time and ids: a network that
///    duplicates datagrams, a sender that retransmits) is refused ("<KIND>:duplicate"). Keys are
///    kept over the out-of-sequence window `window_s`; an older input is refused as too old anyway.

#include <optional>
#include <set>

#include "common/diagnostics.h"
#include "common/time_guard.h"
#include "estimator/core/estimator_options.h"
#include "estimator/node/estimator_input.h"

namespace meshnav::estimator {

class InputGate {
 public:
  enum class Verdict {
    kRefused,   ///< drop the input (counted)
    kAdmitted,  ///< go on
    kClockBack  ///< admitted, after the clock jumped backwards: the node starts over first
  };

  /// `options` and `diag` must outlive the gate (the node's own).
  InputGate(const EstimatorOptions& options, Diagnostics& diag);

  /// False (counted "bad_input" with a message naming channel, time and value) for a value no
  /// sensor gives: non-finite, beyond the plausibility limits (common/plausibility.h), a range
  /// outside [−0.5, uwb.max_range_m] m or between invalid ids, a corrected range more than
  /// kMaxRangeCorrection_m from the raw one, an ANCHOR_INIT with bad values.
  bool valid(const EstimatorInput& in);
  /// The time guard on `in` (a command far from the current time is restamped to it).
  Verdict admitTime(EstimatorInput& in);
  /// False (counted "<KIND>:duplicate") when an input with the same key came within the window
  /// before `newest`.
  bool admitOnce(const EstimatorInput& in, const std::optional<Timestamp>& newest);
  /// Forgets the duplicate keys (a reset of the node; the clock stays).
  void forgetKeys() { seen_.clear(); }

  /// With uwb.use_corrected_range, a correction larger than this is no correction (a source that
  /// leaves range_corr at 0, like old serial-bridge logs and real-t1-a3-loiter) [m].
  static constexpr double kMaxRangeCorrection_m = 1.0;

 private:
  const EstimatorOptions& options_;
  Diagnostics& diag_;
  TimeGuard time_guard_;
  std::set<InputOrder> seen_;  ///< keys of the inputs admitted within the window
};

}  // namespace meshnav::estimator
