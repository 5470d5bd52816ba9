#include "estimator/uwb/uwb_network.h"

#include <cmath>

namespace meshnav::estimator {

UwbNetwork::UwbNetwork(const SystemSetup& setup, double fallback_sigma_m, double uncalibrated_gamma_sigma_m)
    : tags_p_TinI_(setup.rel_tag_positions),
      setup_sigma_m_(setup.noise.sigma_range_m),
      fallback_sigma_m_(fallback_sigma_m),
      clock_offset_s_(setup.uwb_clock.offset_s) {
  for (const auto& [id, p] : setup.abs_anchor_positions)
    if (!setup.abs_anchor_sigmas_m.count(id)) exact_anchors_p_AinG_[id] = p;
  for (const PairBias& b : setup.pair_biases) setPairBias(b);
  if (uncalibrated_gamma_sigma_m > 0.0)
    for (const auto& [tag, lever] : tags_p_TinI_)
      for (const auto& [anchor, p] : exact_anchors_p_AinG_) {
        if (hasPairBias(tag, anchor)) continue;
        PairBias b;
        b.a = tag;
        b.b = anchor;
        b.sigma_m = 0.0;  // the range σ from rangeSigma's fallbacks, as for any unlisted pair
        b.sigma_gamma_m = uncalibrated_gamma_sigma_m;
        setPairBias(b);
      }
}

const Eigen::Vector3d* UwbNetwork::tagLeverArm(SensorId id) const {
  auto it = tags_p_TinI_.find(id);
  return it == tags_p_TinI_.end() ? nullptr : &it->second;
}

const Eigen::Vector3d* UwbNetwork::exactAnchor(SensorId id) const {
  auto it = exact_anchors_p_AinG_.find(id);
  return it == exact_anchors_p_AinG_.end() ? nullptr : &it->second;
}

PairBias UwbNetwork::pairBias(SensorId a, SensorId b) const {
  auto it = biases_.find(pairKey(a, b));
  if (it != biases_.end()) return it->second;
  PairBias none;
  none.a = a;
  none.b = b;
  none.gamma_m = 0.0;
  none.beta = 1.0;
  none.sigma_m = 0.0;
  return none;
}

double UwbNetwork::rangeSigma(SensorId a, SensorId b, double R_m2) const {
  auto it = biases_.find(pairKey(a, b));
  if (it != biases_.end() && it->second.sigma_m > 0.0) return it->second.sigma_m;
  if (setup_sigma_m_ && *setup_sigma_m_ > 0.0) return *setup_sigma_m_;
  if (R_m2 > 0.0 && std::isfinite(R_m2)) return std::sqrt(R_m2);
  return fallback_sigma_m_;
}

}  // namespace meshnav::estimator
