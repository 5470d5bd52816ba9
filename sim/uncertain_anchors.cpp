#include "sim/uncertain_anchors.h"

#include <random>
#include <stdexcept>

#include "sim/paper_scenario.h"
#include "sim/uwb_hardware_biases.h"

namespace meshnav::sim {

int makeAnchorsUncertain(Dataset& ds, const UncertainAnchorOptions& o, const UwbHardwareOptions& hardware,
                         double sigma_range_m) {
  if (!ds.truth) throw std::invalid_argument("makeAnchorsUncertain: the dataset has no truth");
  if (!(o.sigma_m > 0.0 && o.sigma_m < 10.0))
    throw std::invalid_argument("uncertain anchor sigma must be in (0, 10) m");
  std::mt19937_64 rng(o.seed * 0x9E3779B97F4A7C15ULL + 0x5EEDULL);
  std::normal_distribution<double> n01(0.0, 1.0);
  SystemSetup& setup = ds.setup;
  int written = 0;
  for (const auto& [id, p] : ds.truth->anchor_positions) {
    const Eigen::Vector3d e(n01(rng), n01(rng), n01(rng));
    if (setup.abs_anchor_positions.count(id) && !o.include_known) continue;
    setup.abs_anchor_positions[id] = p + o.sigma_m * e;
    setup.abs_anchor_sigmas_m[id] = o.sigma_m;
    ++written;
  }
  // Known-but-uncertain anchors come with their a-priori pair biases, like 101–104: every pair
  // of devices gets the hardware bias plus the same calibration error model (σ_γ in setup).
  const auto ids = PaperScenario::paper().uwbDeviceIds();
  const UwbHardwareBiases hw(ids, hardware);
  for (size_t i = 0; i < ids.size(); ++i)
    for (size_t j = i + 1; j < ids.size(); ++j)
      if (!setup.findPairBias(ids[i], ids[j]) && !(setup.isTag(ids[i]) && setup.isTag(ids[j])))
        setup.pair_biases.push_back(hw.calibrated(ids[i], ids[j], sigma_range_m));
  return written;
}

}  // namespace meshnav::sim
