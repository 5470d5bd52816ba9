#pragma once
/// @file filter_context.h
/// @brief FilterContext: everything a rewind restores, and the one place that replaces the IMU block
/// of the filter (a recovery, a mirror reflection, a gravity flip, an injected fault).
///
/// The node keeps one current context and, per stored input, a shared immutable copy of the
/// context before it (InputTimeline). A copy is cheap: `FusionStrategy::clone()` copies pointers to
/// copy-on-write instances for dp/dah, the network is shared. What a rewind does *not* restore is
/// stated by what is not here: the monitors' windows (health, recovery, gravity direction,
/// re-entry fates), the initializers' buffers, the counters and the output schedule. They observe
/// the inputs in arrival order, not the filter's replays.

#include <memory>
#include <optional>

#include "common/messages.h"
#include "common/types.h"
#include "estimator/core/estimator_options.h"
#include "estimator/core/imu_state.h"
#include "estimator/filter/fusion_strategy.h"
#include "estimator/imu/imu_readings.h"
#include "estimator/imu/process_noise_adapter.h"
#include "estimator/uwb/range_error_correlation.h"
#include "estimator/uwb/uwb_network.h"
#include "estimator/zupt/rest_rate_mean.h"

namespace meshnav::estimator {

struct FilterContext {
  std::unique_ptr<FusionStrategy> filter;  ///< null before the initialization
  std::shared_ptr<const UwbNetwork> network;
  std::optional<ImuSample> last_imu;
  std::optional<ImuSample> prev_imu;  ///< the sample before last_imu (the extrapolation's slope)
  bool landed = true;
  Timestamp last_zupt;
  RestRateMean rest_rate;  ///< gyro readings since last_zupt while landed (the ZUPT's ω row)
  Timestamp last_carried_height;  ///< last carried-height pseudo-reading (IMU time)
  ProcessNoiseAdapter noise_adapter;  ///< IMU noise scale from the range innovations
  RangeErrorCorrelation range_errors;  ///< each pair's newest range (the R inflation of the next)
  /// Low-passed (time constant imu.gap_mean_time_constant_s) acceleration and angular rate in
  /// G (`acc_m_s2` = R̂(a_m − b̂_a) + g, `gyro_rad_s` = R̂(ω_m − b̂_ω)): what an IMU gap is
  /// propagated on with imu.gap_readings "mean" (the rate's vertical part only).
  std::optional<ImuReading> mean_reading;

  FilterContext copy() const;

  /// Replaces the IMU instance by (x, P) at `t`, `last_imu` the sample it continues from. Every
  /// other instance keeps its mean and the marginal covariance its kind keeps
  /// (`K::keptCovariance`: the baro bias, which may have absorbed a runaway, widens to its init σ);
  /// cross-covariances restart from zero, DAH joint sets stay together. The low-passed reading,
  /// the extrapolation's slope and the ZUPT's rest-rate mean restart (they were in the old frame).
  void replaceImu(const ImuState& x, const ImuMatrix& P, Timestamp t, const ImuSample& last_imu,
                  const EstimatorOptions& options, SensorId imu_id, double gravity_z_sign);
};

}  // namespace meshnav::estimator
