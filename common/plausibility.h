#pragma once
/// @file plausibility.h
/// @brief The one table of plausibility limits for raw sensor values. Every reader (dataset CSVs,
/// serial lines, LCM messages) and every node uses these, so a value refused in one layer is
/// refused in all of them. Values beyond a limit are bad input: reported with file and line or
/// channel, counted, and dropped (never clamped).

namespace meshnav::plausible {

/// |specific force| above ~50 g is no IMU reading in this domain (MEMS full scale is 16 g) [m/s²].
constexpr double kMaxSpecificForce_m_s2 = 500.0;
/// |angular rate| above ~2900 deg/s (MEMS full scale is 2000 deg/s) [rad/s].
constexpr double kMaxAngularRate_rad_s = 50.0;
/// Barometric pressure interval [Pa]: far above the highest summit, below any weather record.
constexpr double kMinPressure_pa = 1000.0;
constexpr double kMaxPressure_pa = 200000.0;
/// UWB range interval [m]: biased short ranges can be slightly negative; beyond 500 m none is real.
constexpr double kMinRange_m = -0.5;
constexpr double kMaxRange_m = 500.0;
/// A range's stated noise variance [m²]: a σ beyond the longest range says nothing.
constexpr double kMaxRangeVariance_m2 = kMaxRange_m * kMaxRange_m;
/// Laser height above the floor [m].
constexpr double kMaxHeight_m = 100.0;

}  // namespace meshnav::plausible
