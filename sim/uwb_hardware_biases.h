#pragma once
/// @file uwb_hardware_biases.h
/// @brief Pairwise SDS-TWR range errors of a fixed set of UWB modules: z = β_ab · d + γ_ab + ν.
///
/// Like real hardware, the biases belong to the devices, not to a flight: they are drawn once from
/// a fixed hardware seed (the same for every sequence), symmetric in (a, b):
///   γ_ab ~ N(0, σ_γ²) clipped to ±γ_max,   β_ab = 1 + clip(N(0, σ_β²), ±β_max).
/// A user's a-priori calibration (as if done on sequence 1) has its own fixed error:
///   γ̂ = γ + N(0, σ_γ,cal²),  β̂ = β + N(0, σ_β,cal²).

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "common/types.h"

namespace meshnav::sim {

struct UwbHardwareOptions {
  uint64_t hardware_seed = 20230831;  ///< fixed: the same modules in every sequence
  double gamma_sigma_m = 0.15;                   ///< σ_γ [m]
  double gamma_max_m = 0.4;                      ///< |γ| ≤ γ_max [m]
  double beta_sigma = 0.004;                     ///< σ_β [-]
  double beta_max_deviation = 0.01;              ///< |β − 1| ≤ β_max [-]
  double calibration_gamma_sigma_m = 0.02;       ///< error of the a-priori calibrated γ̂ [m]
  double calibration_beta_sigma = 0.0005;        ///< error of the a-priori calibrated β̂ [-]
  std::string toString() const;
};

class UwbHardwareBiases {
 public:
  UwbHardwareBiases(const std::vector<SensorId>& device_ids, const UwbHardwareOptions& options = {});

  /// True bias of the unordered pair (a, b). Throws std::out_of_range for an unknown pair.
  const PairBias& truth(SensorId a, SensorId b) const;
  /// A-priori calibrated bias of (a, b) (truth + fixed calibration error); sigma fields describe it.
  PairBias calibrated(SensorId a, SensorId b, double sigma_range_m) const;
  /// All true pair biases, sorted by (a, b) with a < b.
  std::vector<PairBias> allTrue(double sigma_range_m) const;
  const UwbHardwareOptions& options() const { return options_; }

 private:
  UwbHardwareOptions options_;
  std::map<std::pair<SensorId, SensorId>, PairBias> truth_;
  std::map<std::pair<SensorId, SensorId>, PairBias> calibrated_;
};

}  // namespace meshnav::sim
