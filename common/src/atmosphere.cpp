#include "common/atmosphere.h"

#include <cmath>

namespace meshnav::atmosphere {

namespace {
constexpr double kExponent = kGravity_m_s2 * kMolarMass_kg_mol / (kGasConstant * kLapseRate_K_m);
}

double heightFromPressure(double p_pa, double p_ref_pa) {
  return (kT0_K / kLapseRate_K_m) * (1.0 - std::pow(p_pa / p_ref_pa, 1.0 / kExponent));
}

double pressureFromHeight(double h_m, double p_ref_pa) {
  return p_ref_pa * std::pow(1.0 - kLapseRate_K_m * h_m / kT0_K, kExponent);
}

double dHeightDPressure(double p_pa, double p_ref_pa) {
  // h = c (1 - (p/pr)^(1/e))  =>  dh/dp = -c/(e pr) (p/pr)^(1/e - 1)
  const double c = kT0_K / kLapseRate_K_m;
  return -c / (kExponent * p_ref_pa) * std::pow(p_pa / p_ref_pa, 1.0 / kExponent - 1.0);
}

}  // namespace meshnav::atmosphere
