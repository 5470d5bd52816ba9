#include "sim/uwb_hardware_biases.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "sim/random_stream.h"

namespace meshnav::sim {

std::string UwbHardwareOptions::toString() const {
  std::ostringstream s;
  s << "uwb hardware: seed " << hardware_seed << ", gamma ~ N(0, " << gamma_sigma_m << "^2) clipped +-"
    << gamma_max_m << " m, beta - 1 ~ N(0, " << beta_sigma << "^2) clipped +-" << beta_max_deviation
    << ", a-priori calibration error " << calibration_gamma_sigma_m << " m / " << calibration_beta_sigma;
  return s.str();
}

UwbHardwareBiases::UwbHardwareBiases(const std::vector<SensorId>& device_ids, const UwbHardwareOptions& options)
    : options_(options) {
  for (size_t i = 0; i < device_ids.size(); ++i) {
    for (size_t j = i + 1; j < device_ids.size(); ++j) {
      const auto key = pairKey(device_ids[i], device_ids[j]);
      // One stream per pair: adding a device does not change the other pairs.
      const std::string name = "pair:" + std::to_string(key.first) + "-" + std::to_string(key.second);
      RandomStream hw(RandomStream::deriveSeed(options_.hardware_seed, name));
      PairBias b;
      b.a = key.first;
      b.b = key.second;
      b.gamma_m = std::clamp(hw.gaussian(options_.gamma_sigma_m), -options_.gamma_max_m, options_.gamma_max_m);
      b.beta = 1.0 + std::clamp(hw.gaussian(options_.beta_sigma), -options_.beta_max_deviation,
                                options_.beta_max_deviation);
      truth_[key] = b;
      RandomStream cal(RandomStream::deriveSeed(options_.hardware_seed, "calibration:" + name));
      PairBias c = b;
      c.gamma_m += cal.gaussian(options_.calibration_gamma_sigma_m);
      c.beta += cal.gaussian(options_.calibration_beta_sigma);
      c.sigma_gamma_m = options_.calibration_gamma_sigma_m;
      c.sigma_beta = options_.calibration_beta_sigma;
      calibrated_[key] = c;
    }
  }
}

const PairBias& UwbHardwareBiases::truth(SensorId a, SensorId b) const {
  const auto it = truth_.find(pairKey(a, b));
  if (it == truth_.end())
    throw std::out_of_range("UwbHardwareBiases: unknown pair " + std::to_string(a) + "-" + std::to_string(b));
  return it->second;
}

PairBias UwbHardwareBiases::calibrated(SensorId a, SensorId b, double sigma_range_m) const {
  const auto it = calibrated_.find(pairKey(a, b));
  if (it == calibrated_.end())
    throw std::out_of_range("UwbHardwareBiases: unknown pair " + std::to_string(a) + "-" + std::to_string(b));
  PairBias c = it->second;
  c.sigma_m = sigma_range_m;
  return c;
}

std::vector<PairBias> UwbHardwareBiases::allTrue(double sigma_range_m) const {
  std::vector<PairBias> out;
  for (const auto& [key, b] : truth_) {
    PairBias c = b;
    c.sigma_m = sigma_range_m;
    out.push_back(c);
  }
  return out;
}

}  // namespace meshnav::sim
