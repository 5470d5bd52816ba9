#pragma once
/// @file fixed_lag_smoother.h
/// @brief Fixed-lag smoothed poses from the filter's own history (issue 35 item 1,
/// docs/smoother.md "The fixed-lag smoother"): a Rauch–Tung–Striebel backward pass over the
/// IMU block of the filter's last `lag_s + period_s` seconds.
///
/// **The chain.** Every propagation of the filter is a record: the IMU block's filtered belief at
/// its start a (x⁺_a, P⁺_a: after every update at t_a), its predicted belief at its end b
/// (x⁻_b, P⁻_b: before any update at t_b) and the error transition Φ_ab (the product of the steps'
/// Φ, FusionStrategy::takeTransition()), so that P⁻_b = Φ_ab P⁺_a Φ_abᵀ + Q_ab whatever Q was (the
/// noise adapter's λ, an IMU gap's noise). What happens at t_b between x⁻_b and the next
/// record's x⁺_b (range, baro, height and zero-velocity updates, a re-run's swap) is an update to
/// the backward pass, which never reads it.
///
/// **The pass.** From the newest filtered belief (x^s = x⁺_N, P^s = P⁺_N) backwards, per record:
///   C_a  = P⁺_a Φ_abᵀ (P⁻_b)⁻¹                       (computed once per record, on first use)
///   x^s_a = x⁺_a ⊞ C_a (x^s_b ⊟ x⁻_b)
///   P^s_a = P⁺_a + C_a (P^s_b − P⁻_b) C_aᵀ            (symmetrized)
/// with ⊞/⊟ the IMU error state's (imu_state.h: δθ local). This is the RTS smoother of the
/// linearized model restricted to the IMU block: it ignores the IMU block's correlation with the
/// other instances (anchors, pair biases, the baro bias, the UWB clock) given the next IMU state,
/// which the modular strategies (dp, dah) do not even form; docs/smoother.md measures what that
/// costs against the whole-recording smoother.
///
/// **Outputs.** Each POSE the node publishes (onPose) is a mark. Every `period_s` of data time a
/// pass starts from the newest belief; it is done a few records per input (its records over half
/// the propagations of a period, at least two), after the input's POSE went out (work()), so that
/// no POSE waits for it.
/// When it reaches the oldest mark it emits, in time order, the smoothed pose of every mark at
/// least `lag_s` older than its start, a few per work() call over the next half period (as evenly
/// as the POSEs came: no burst on the bus): the lag is between lag_s and about lag_s + 2 period_s.
/// A mark the chain does not reach (no record boundary at its time: before the first
/// propagation, or across a gap in the chain) goes out as the filter gave it, counted
/// `fixed_lag_unsmoothed`. finish() emits every mark left (the end of a stream, a
/// re-initialization: the chain ends there).
///
/// **History changes.** A record that starts before the newest record's end (a late input's
/// rewind, a re-run on an anchor join) drops the records after its start (and a pass that still
/// needed them, which the next one replaces); the replay then records the new history. A record
/// is only kept when it ends after the oldest mark still to be emitted (wants()): a re-run's replay
/// of minutes records only its last seconds, and memory is bounded by about
/// (lag_s + 2 period_s) × the propagation rate (about 1300 records of 7.5 kB at 300 propagations/s).
///
/// Free of LCM and of the node: EstimatorNode feeds it (estimator_node.cpp, propagateRecorded).

#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <vector>

#include "common/diagnostics.h"
#include "common/types.h"
#include "estimator/core/estimator_options.h"
#include "estimator/core/imu_state.h"

namespace meshnav::estimator {

/// The IMU block of the filter at one instant: mean and covariance (ImuErr order).
struct ImuBelief {
  Timestamp t;
  ImuState x;
  ImuMatrix P = ImuMatrix::Zero();
};

class FixedLagSmoother {
 public:
  using Sink = std::function<void(const PoseEstimate&)>;
  /// On when options.lag_s > 0 and there is a sink. Throws std::invalid_argument for lag_s < 0 or
  /// period_s ≤ 0.
  FixedLagSmoother(const FixedLagOptions& options, Diagnostics& diag, Sink sink = {});

  bool enabled() const { return enabled_; }
  const FixedLagOptions& options() const { return options_; }

  /// Whether a propagation starting at `from_t` is needed (else the node may call skip() and save
  /// taking the beliefs): it ends after the oldest mark still to be emitted, or there is none.
  bool wants(Timestamp from_t) const {
    return enabled_ && (marks_.empty() || from_t >= Timestamp{marks_.begin()->first});
  }
  /// A propagation from `from_t` that is not recorded: the history after `from_t` is dropped.
  void skip(Timestamp from_t) { truncateAfter(from_t); }
  /// The filter propagated from `from` to `to` with error transition `Phi`. A pass starts first
  /// when one is due (`from` is then the newest belief, after every update at its time).
  void onPropagation(const ImuBelief& from, const ImuBelief& to, const ImuMatrix& Phi);
  /// A running pass goes on by its share of records (Pass::steps): the node calls it after an
  /// input's outputs (its POSE) are out, so that the pass never delays one.
  void work();
  /// The node published `pose`: its smoothed twin is emitted once the data is `lag_s` past it.
  void onPose(const PoseEstimate& pose);
  /// The chain ends with the filter's belief `last` (the end of the stream, a re-initialization
  /// that replaces the IMU block): every mark left is emitted, smoothed from `last`, and the
  /// records are dropped.
  void finish(const ImuBelief& last);
  /// Forgets everything, marks included (the node starts over).
  void reset();

  /// Records held (for tests: memory stays bounded).
  size_t recordCount() const { return records_.size(); }
  /// Marks waiting for their lag.
  size_t pendingCount() const { return marks_.size(); }

 private:
  struct Record {
    ImuBelief from;  ///< filtered, after the updates at from.t
    ImuBelief to;    ///< predicted, before the updates at to.t
    ImuMatrix Phi;
    std::optional<ImuMatrix> gain;  ///< C = P⁺_a Φᵀ (P⁻_b)⁻¹, on first use
    bool gain_failed = false;       ///< P⁻_b not positive definite: the chain restarts here
  };
  /// A backward pass under way: the smoothed belief reached so far, and what it found.
  struct Pass {
    ImuBelief s;           ///< smoothed; the next record is the one ending at s.t
    Timestamp emit_until;  ///< marks at or before it are emitted
    std::map<int64_t, PoseEstimate> out;  ///< by µs: the smoothed marks found so far
    int steps = 2;  ///< records per call: the pass's records over half the last period's propagations
    size_t calls_per_period = 1;  ///< propagations in the last period (a proxy for work() calls)
  };
  /// Starts a pass from `newest`, finishing one still running first.
  void startPass(const ImuBelief& newest, Timestamp emit_until);
  /// At most `max_steps` records of the running pass (< 0: all); at its end its poses go out.
  void continuePass(int max_steps);
  /// Drops the records ending after `t` (and a running pass that needed one of them).
  void truncateAfter(Timestamp t);
  /// The RTS step over `r` from the smoothed belief at its end; false when its gain is unusable.
  bool smoothStep(Record& r, const ImuBelief& at_end, ImuBelief& at_start);
  /// Drops the records no mark needs any more.
  void prune();
  /// The pass found the smoothed belief `b`: kept when a mark due is at its time.
  void take(const ImuBelief& b);
  /// The pass is done: every mark due goes out, smoothed when the pass found it.
  void endPass();
  /// Queues `e` for the sink (ready_).
  void emit(const PoseEstimate& e);
  /// Every queued pose to the sink now.
  void release();

  FixedLagOptions options_;
  bool enabled_;
  Diagnostics& diag_;
  Sink sink_;
  std::deque<Record> records_;
  std::map<int64_t, PoseEstimate> marks_;  ///< by µs: the filter's POSEs still to be smoothed
  std::optional<Pass> pass_;
  std::deque<PoseEstimate> ready_;  ///< smoothed poses of an ended pass, going out a few per work()
  int release_per_call_ = 1;
  std::optional<Timestamp> last_pass_;
  std::optional<Timestamp> last_emitted_;
};

/// A belief of the IMU block as a POSE: its mean and the marginal covariances of p, v and θ (also
/// the filter's own POSE, poseOf in node/output_schedule.h).
PoseEstimate poseOfBelief(const ImuBelief& b);

}  // namespace meshnav::estimator
