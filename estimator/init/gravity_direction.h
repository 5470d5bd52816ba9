#pragma once
/// @file gravity_direction.h
/// @brief Which way gravity points in the anchors' frame G (docs/robustness.md, "Which way is
/// up"): along −z (the convention every model assumes) or along +z (an anchor survey whose z axis
/// points down, as ISAS-Walk1's).
///
/// The model: the frame G is fixed by the anchors; gravity is g_G = (0, 0, s|g|) with an unknown
/// sign s ∈ {−1, +1} that no Gaussian state can carry (the two hypotheses are 2|g| apart). Both
/// hypotheses are compared by the motion aligner's cost over one window of ranges and IMU
/// increments (MotionAligner::checkGravityDirection: a decisive cost difference beyond its margin
/// decides; otherwise undecided). The comparison runs
///  - while undecided, each time the data since the first initialization has doubled: after
///    `init.motion_min_span_s` (the shortest window the aligner fits), then after twice as long
///    again, the step capped at `init.motion_window_s` (3, 9, 21, 33 s after it with the defaults),
///    at most `kMaxChecks` times. An undecided window becomes decisive as the motion it holds grows;
///    with a fixed step of a window a late-started upside-down walk flew 12 s on the wrong side
///    (the NLOS mixture keeps the early check below from firing there: 35 s → 26 s, max error
///    0.67 → 0.44 m, 2026-12-06);
///  - earlier, once, when the range innovations say the model is far off before that: a median
///    range NIS of `init.gravity_early_check_nis_ratio` times its expected value (a wrong sign
///    shows there first: ISAS-Walk1 started mid-walk reaches 12× within 2 s).
/// The first in-motion alignment compares both signs on its own window and starts along the one
/// that fits decisively better (Initialization, InitialBelief::gravity_z_sign): then nothing above
/// is scheduled. Baro and heights measure along −z of G: with them the frame is taken as it is (a
/// warning only).
/// Once +z wins, s = +1 from then on and the pose is re-initialized by the aligner with it
/// (anchors and biases kept), retried every `kFlipRetry_s` while the aligner refuses.
///
/// Not thread-safe; the node calls it from its thread. The node's part is the `Context`.

#include <optional>
#include <string>

#include <Eigen/Core>

#include "common/diagnostics.h"
#include "common/time.h"
#include "estimator/init/motion_aligner.h"

namespace meshnav::estimator {

class GravityDirection {
 public:
  /// What the check needs from the node.
  class Context {
   public:
    virtual ~Context() = default;
    /// The aligner's comparison of both signs over its current window (timed by the node);
    /// nullopt when it cannot compare (`whyNot` says why).
    virtual std::optional<MotionAligner::GravityCheck> compareGravitySigns() = 0;
    virtual std::string whyNot() const = 0;
    /// Baro readings or heights seen (both measure along −z of G).
    virtual bool hasVerticalSensor() const = 0;
    /// Gravity is along +z from now on: the node's models that hold g (aligner, ZUPT) switch.
    virtual void gravityTurned() = 0;
    /// Re-initializes the pose with gravity along +z at `t` (anchors and biases kept); false when
    /// the aligner refuses now.
    virtual bool reinitializeWithGravity(Timestamp t) = 0;
    /// The latest median range NIS over its expected value (for the log).
    virtual double rangeNisRatio() const = 0;
  };

  /// At most this many scheduled comparisons while undecided (little motion in the window) [-].
  static constexpr int kMaxChecks = 4;
  /// A re-initialization the aligner refused is tried again after this long [s].
  static constexpr double kFlipRetry_s = 0.5;

  /// `first_s`: init.motion_min_span_s, the first comparison's delay; `window_s`: init.motion_window_s,
  /// the longest step between two; `early_nis_ratio`: init.gravity_early_check_nis_ratio (0: off).
  GravityDirection(double first_s, double window_s, double early_nis_ratio, Diagnostics& diag);

  /// Back to the convention (gravity along −z), nothing scheduled (a reset of the node).
  void reset();
  /// s: −1 (along −z of G, the convention) or +1.
  double zSign() const { return sign_; }
  /// A re-run's replay node: the live node's sign (the replay runs no comparison).
  void takeSignOf(const GravityDirection& live) { sign_ = live.sign_; }
  /// Gravity in G [m/s²] for |g| = `g_m_s2`.
  Eigen::Vector3d gravityG(double g_m_s2) const { return {0.0, 0.0, sign_ * g_m_s2}; }

  /// The filter was initialized at `t`: the first comparison is scheduled `first_s` later (once).
  /// `decided_sign` (InitialBelief::gravity_z_sign): the first in-motion alignment compared both
  /// signs on its window and one fitted decisively better (+1: along +z, taken from now on; −1:
  /// along −z); nothing is scheduled then. 0: not compared there, or undecided.
  void onInitialized(Timestamp t, int decided_sign = 0);
  /// A batch's median range NIS over its expected value (the process-noise adapter's): at or above
  /// the early ratio before the first comparison, the comparison runs at the next IMU sample.
  void noteRangeNisRatio(double ratio);
  /// Runs what is due at IMU time `t`: the early comparison, the scheduled one, a pending
  /// re-initialization.
  void onImu(Timestamp t, Context& c);

 private:
  void scheduledCheck(Timestamp t, Context& c);
  /// The next comparison: the step doubled (first_s at the first), capped at window_s.
  void scheduleNext(Timestamp t);
  void earlyCheck(Timestamp t, Context& c);
  void takePlusZ(Timestamp t, const MotionAligner::GravityCheck& check, Context& c);
  void tryReinitialize(Timestamp t, Context& c);

  double first_s_, window_s_, early_nis_ratio_;
  double step_s_ = 0.0;                ///< the last step between scheduled comparisons
  Diagnostics& diag_;
  double sign_ = -1.0;
  std::optional<Timestamp> check_at_;  ///< when the scheduled comparison runs
  int checks_ = 0;                     ///< comparisons run (scheduled, and an early one that decided)
  bool early_due_ = false, early_checked_ = false;
  bool reinit_pending_ = false;        ///< +z taken, the pose not re-initialized with it yet
  std::optional<Timestamp> last_reinit_try_;
};

}  // namespace meshnav::estimator
