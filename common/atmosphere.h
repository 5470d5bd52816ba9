#pragma once
/// @file atmosphere.h
/// @brief International standard atmosphere (troposphere) used by the barometer model.
///
/// p(h) = p_ref · (1 − L·h / T0)^(g·M / (R·L)),  h = (T0 / L) · (1 − (p / p_ref)^(R·L / (g·M)))
/// with L = 0.0065 K/m, T0 = 288.15 K, g = 9.80665 m/s², M = 0.0289644 kg/mol, R = 8.3144598 J/(mol·K).
/// h is the height above the level where the pressure is p_ref.

namespace meshnav::atmosphere {

constexpr double kLapseRate_K_m = 0.0065;
constexpr double kT0_K = 288.15;
constexpr double kGravity_m_s2 = 9.80665;
constexpr double kMolarMass_kg_mol = 0.0289644;
constexpr double kGasConstant = 8.3144598;
constexpr double kSeaLevelPressure_Pa = 101325.0;

/// Height [m] above the reference level for pressure `p_pa` given the reference pressure.
double heightFromPressure(double p_pa, double p_ref_pa);
/// Pressure [Pa] at height `h_m` above the reference level.
double pressureFromHeight(double h_m, double p_ref_pa);
/// d h / d p [m/Pa] at pressure `p_pa` (≈ −0.083 m/Pa near sea level): maps a pressure σ to a height σ.
double dHeightDPressure(double p_pa, double p_ref_pa);

}  // namespace meshnav::atmosphere
