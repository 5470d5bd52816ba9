/// @file initial_states.cpp
/// @brief The instances an initialization adds besides the IMU: setup anchors known with an
/// uncertainty, and the tags' pair biases.
#include "estimator/init/initial_states.h"

#include <vector>

namespace meshnav::estimator {

void addSetupAnchorStates(FusionStrategy& f, const SystemSetup& setup, const UwbOptions& uwb) {
  for (const auto& [id, p] : setup.abs_anchor_positions) {
    auto sig = setup.abs_anchor_sigmas_m.find(id);
    if (sig == setup.abs_anchor_sigmas_m.end()) continue;
    // Known-but-uncertain: its a-priori γ towards exactly known anchors and towards uncertain
    // anchors of smaller id (one owner per pair) become states too (independent a priori).
    BiasState biases;
    std::vector<double> gamma, var = {1.0, 1.0, 1.0};
    if (uwb.estimate_setup_anchor_biases) {
      for (const auto& [peer, q] : setup.abs_anchor_positions) {
        if (peer == id || (setup.abs_anchor_sigmas_m.count(peer) && peer > id)) continue;
        const auto pb = setup.findPairBias(id, peer);
        if (!pb || pb->sigma_gamma_m <= 0.0) continue;
        biases.peers.push_back(peer);
        gamma.push_back(pb->gamma_m);
        var.push_back(pb->sigma_gamma_m * pb->sigma_gamma_m);
      }
    }
    biases.gamma_m = Eigen::Map<const Eigen::VectorXd>(gamma.data(), static_cast<Eigen::Index>(gamma.size()));
    Eigen::VectorXd v = Eigen::Map<const Eigen::VectorXd>(var.data(), static_cast<Eigen::Index>(var.size()));
    v.head<3>() *= sig->second * sig->second;
    f.addInstance<AnchorKind>(id, AnchorState{p, biases}, v.asDiagonal().toDenseMatrix());
  }
}

void addTagBiasStates(FusionStrategy& f, const SystemSetup& setup, const UwbOptions& uwb) {
  if (!uwb.estimate_tag_biases) return;
  // Tag instances with state: γ towards the setup's anchors (exact or known-but-uncertain) whose
  // a-priori bias is uncertain. Constant per pair, so a state rather than white noise. The
  // unlisted pairs of one tag share the prior of their common offset c_tag (σ_c² in every entry
  // among them): γ = c_tag + e, docs/uwb_bias_model.md.
  const double var_c = uwb.uncalibrated_gamma_sigma_m > 0.0
                           ? uwb.uncalibrated_common_gamma_sigma_m * uwb.uncalibrated_common_gamma_sigma_m
                           : 0.0;
  for (const auto& [tag, lever] : setup.rel_tag_positions) {
    std::vector<SensorId> peers;
    std::vector<double> gamma, var;
    std::vector<bool> uncalibrated;
    for (const auto& [anchor, p] : setup.abs_anchor_positions) {
      const auto pb = setup.findPairBias(tag, anchor);
      // A listed pair: its a-priori γ and σ_γ (exact when σ_γ = 0). An unlisted one: unknown,
      // N(0, uncalibrated_gamma_sigma_m²).
      const double mean = pb ? pb->gamma_m : 0.0;
      const double sigma = pb ? pb->sigma_gamma_m : uwb.uncalibrated_gamma_sigma_m;
      if (sigma <= 0.0) continue;
      peers.push_back(anchor);
      gamma.push_back(mean);
      var.push_back(sigma * sigma);
      uncalibrated.push_back(!pb);
    }
    if (peers.empty()) continue;
    Eigen::MatrixXd P = Eigen::Map<Eigen::VectorXd>(var.data(), static_cast<long>(var.size())).asDiagonal();
    for (size_t i = 0; i < peers.size(); ++i)
      for (size_t j = 0; j < peers.size(); ++j)
        if (uncalibrated[i] && uncalibrated[j]) P(i, j) += var_c;
    f.addInstance<TagBiasKind>(
        tag, BiasState{peers, Eigen::Map<Eigen::VectorXd>(gamma.data(), static_cast<long>(gamma.size()))}, P);
  }
}

}  // namespace meshnav::estimator
