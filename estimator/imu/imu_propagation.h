#pragma once
/// @file imu_propagation.h
/// @brief The filter's propagation on the IMU's readings, between samples and across gaps
/// (ImuNoiseOptions, docs/robustness.md "IMU gaps").
///
/// Models:
///  - **Between samples**: the readings interpolated to the middle of the step (readingBetween),
///    also to a measurement's time when the sample after it is known (`next_imu`: with
///    `imu.hold_for_next_sample` the node holds a measurement until that sample comes). The two
///    parts of a step cut at a measurement then integrate the samples' linear interpolant
///    exactly, as the uncut step does.
///  - **Past the last sample** (the default; with the hold only without a next sample within
///    `imu.max_dt_s`: an IMU gap, the end of a stream): extrapolated along the last two samples
///    (readingPast, at most `imu.extrapolate_max_period_s`, its extra noise scale with it).
///  - **Extra white noise**: the innovation-driven scale λ of the stated densities
///    (ProcessNoiseAdapter) adds (λ − 1 + λ s_u) σ² to the discrete noise of the step, s_u the
///    reading's own excess (extrapolated readings): Q_v = q_a dt I, Q_θ = q_ω dt I, Q_p = q_a dt³/3 I,
///    Q_pv = q_a dt²/2 I (whiteImuNoise).
///  - **Gaps**: beyond `imu.max_dt_s` after the last sample there is no reading. The part of the
///    step in the gap is propagated on `imu.gap_readings`: "mean" (the low-passed acceleration in G
///    and the turn rate about the vertical, no tilting), "still" (a = 0 in G, ω = 0) or "held" (the
///    last reading), with its error as white noise of `imu.gap_sigma_acc_m_s2` and
///    `imu.gap_sigma_gyro_rad_s` over the gap.
///  - **The low-passed reading** (for "mean"): a_G = R̂(a_m − b̂_a) + g_G and ω_G = R̂(ω_m − b̂_ω),
///    first-order low-passed with time constant `imu.gap_mean_time_constant_s`, restarted after a gap.

#include <optional>

#include <Eigen/Core>

#include "common/types.h"
#include "estimator/core/estimator_options.h"
#include "estimator/filter/fusion_strategy.h"
#include "estimator/imu/imu_readings.h"

namespace meshnav::estimator {

class ImuPropagation {
 public:
  explicit ImuPropagation(const ImuNoiseOptions& options) : options_(options) {}

  /// What a propagation reads besides the filter: the last IMU samples, the low-passed reading,
  /// gravity in G and the noise scale λ.
  struct Inputs {
    const std::optional<ImuSample>& last_imu;
    const std::optional<ImuSample>& prev_imu;  ///< the sample before last_imu
    const std::optional<ImuReading>& mean_reading;
    Eigen::Vector3d g_G;
    double lambda = 1.0;
    /// The sample after a measurement's time, when known: the readings up to the measurement are
    /// interpolated towards it instead of extrapolated past last_imu.
    const ImuSample* next_imu = nullptr;
  };
  /// Propagates `f` to IMU sample `s` (readings interpolated between the last sample and `s`).
  void toSample(FusionStrategy& f, const ImuSample& s, const Inputs& in) const;
  /// Propagates `f` to a measurement time `t` past the last IMU sample: readings interpolated
  /// towards `in.next_imu` when it is at or after `t` and at most `imu.max_dt_s` after the last
  /// sample, else extrapolated (readingPast).
  void toTime(FusionStrategy& f, Timestamp t, const Inputs& in) const;
  /// Propagates on readings `u` held over [filter time, t], with the gap model beyond
  /// `imu.max_dt_s` after the last sample.
  void propagate(FusionStrategy& f, const ImuReading& u, Timestamp t, const Inputs& in) const;
  /// Updates the low-passed reading `mean` with sample `s` at the filter's state `x`.
  void updateMean(std::optional<ImuReading>& mean, const ImuState& x, const ImuSample& s,
                  const std::optional<ImuSample>& previous, const Eigen::Vector3d& g_G) const;

 private:
  /// One propagation on `u` with the innovation-driven extra noise (no gap handling).
  void step(FusionStrategy& f, const ImuReading& u, Timestamp t, double lambda) const;
  ImuNoiseOptions options_;
};

}  // namespace meshnav::estimator
