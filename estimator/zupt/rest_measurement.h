#pragma once
/// @file rest_measurement.h
/// @brief The zero-velocity pseudo-measurement at an IMU reading while the body rests, with the
/// noise of the evidence of rest (ZuptModel linearizes it).
///
/// Rows: v = 0 (σ_v), a_m = −R̂ᵀ g + b_a (σ_a), and ω = 0 on the mean gyro reading ω̄ since the
/// last ZUPT (RestRateMean over T seconds) with σ_ω̄² = σ_rest² + σ_g² λ / T, σ_g the gyro white
/// noise density, λ the IMU noise scale (ProcessNoiseAdapter), σ_rest the rotation a resting body
/// may still have. Before any interval: the latest reading, σ the larger of σ_rest and the
/// stillness σ. Only a FLIGHT_STATE says v = 0 and ω = 0 exactly (`zupt.sigma_vel_m_s`,
/// `zupt.sigma_gyro_rad_s`, not gated); on the IMU's stillness alone a smooth hover or a slowly
/// pushed rig may drift (`zupt.stillness_sigma_*`) and the update is χ²-gated
/// (`zupt.stillness_gate_probability`): an IMU cannot tell rest from constant velocity.

#include "common/messages.h"
#include "estimator/core/estimator_options.h"
#include "estimator/zupt/rest_rate_mean.h"
#include "estimator/zupt/zupt_measurement.h"

namespace meshnav::estimator {

/// `flight_state`: the rest comes from a FLIGHT_STATE (else from IMU stillness).
ZuptMeasurement restMeasurement(const ImuSample& s, const RestRateMean& rest, const ZuptOptions& o,
                                double gyro_noise_density, double noise_scale, bool flight_state);
/// The χ² gate of a rest update of `dim` rows: 0 (none) with a flight state.
double restGate(int dim, const ZuptOptions& o, bool flight_state);

}  // namespace meshnav::estimator
