#pragma once
/// @file clock_offset_kind.h
/// @brief Instance kind of the UWB clock's offset against the IMU clock (estimator/core/kind_traits.h,
/// issue 34 item 1): one error state δ_u = δ̂_u + δδ_u [s], the delay of the UWB stamps: a range
/// stamped t (UWB clock) was measured at the IMU-clock instant t − δ_u. The range model moves the
/// tag to that instant to first order (estimator/uwb/range_model.h; derivation in
/// docs/uwb_bias_model.md, "Clock offset"); the state is observable whenever the tag moves along the
/// line of sight of its ranges and keeps its prior while the tag stands still.
///
/// One instance per estimator (one UWB clock per vehicle), id `uwb_clock_id` of setup.yaml, prior
/// from setup.yaml `uwb_clock` (mean offset_s, σ sigma_s) or `uwb.clock_offset_sigma_s`; absent
/// when that σ is 0 (the clocks are one, or the offset is known: then setup's offset_s is applied
/// as a constant). Random walk `uwb.clock_offset_rw_s_per_sqrt_s` (two free-running clocks drift);
/// kept across a restart and a recovery (the clocks did not change).

#include <Eigen/Core>

#include "common/setup.h"
#include "estimator/core/estimator_options.h"
#include "estimator/core/kind_traits.h"

namespace meshnav::estimator {

struct ClockOffsetKind : ScalarStateKind<ClockOffsetKind> {
  static constexpr const char* kName = "uwb_clock";
  static double randomWalk(const EstimatorOptions& o) { return o.uwb.clock_offset_rw_s_per_sqrt_s; }
  /// A recovery follows a pose that ran away, not a clock that jumped: the offset and its variance
  /// are kept.
  static Eigen::MatrixXd keptCovariance(const Eigen::MatrixXd& cov, const EstimatorOptions&) { return cov; }
  static Restart restart(const EstimatorOptions&) { return Restart::kKept; }
  /// The prior σ of δ_u [s]: setup.yaml `uwb_clock.sigma_s`, else `uwb.clock_offset_sigma_s`; 0:
  /// no state.
  static double priorSigma(const SystemSetup& setup, const EstimatorOptions& o) {
    return setup.uwb_clock.sigma_s.value_or(o.uwb.clock_offset_sigma_s);
  }
};

}  // namespace meshnav::estimator
