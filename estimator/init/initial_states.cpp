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
  if (uwb.estimate_tag_biases) {
    // Tag instances with state: γ towards the setup's anchors (exact or known-but-uncertain) whose
    // a-priori bias is uncertain. Constant per pair, so a state rather than white noise.
    for (const auto& [tag, lever] : setup.rel_tag_positions) {
      std::vector<SensorId> peers;
      std::vector<double> gamma, var;
      for (const auto& [anchor, p] : setup.abs_anchor_positions) {
        const auto pb = setup.findPairBias(tag, anchor);
        if (!pb || pb->sigma_gamma_m <= 0.0) continue;
        peers.push_back(anchor);
        gamma.push_back(pb->gamma_m);
        var.push_back(pb->sigma_gamma_m * pb->sigma_gamma_m);
      }
      if (!peers.empty())
        f.addInstance<TagBiasKind>(
            tag, BiasState{peers, Eigen::Map<Eigen::VectorXd>(gamma.data(), static_cast<long>(gamma.size()))},
            Eigen::Map<Eigen::VectorXd>(var.data(), static_cast<long>(var.size())).asDiagonal().toDenseMatrix());
    }
  }
}

}  // namespace meshnav::estimator
