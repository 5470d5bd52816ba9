#pragma once
/// @file uwb_network.h
/// @brief What the estimator knows about the UWB devices besides the filter state: tag lever arms,
/// exactly known anchors, and the pairwise bias dictionary {(a, b) → γ, β, σ} (symmetric).
/// Changes at run time (ANCHOR_INIT adds biases); the node keeps it copy-on-write so that
/// out-of-sequence rewinds see the dictionary as it was.

#include <Eigen/Core>
#include <map>
#include <optional>
#include <set>
#include <utility>

#include "common/setup.h"
#include "common/types.h"

namespace meshnav::estimator {

class UwbNetwork {
 public:
  UwbNetwork() = default;
  /// Tags and biases from `setup`; anchors in setup.abs_anchor_positions without a σ in
  /// setup.abs_anchor_sigmas_m are exact. `fallback_sigma_m` is the config range σ. A pair of a
  /// tag and an exact anchor that setup.pair_biases does not list gets γ = 0 with σ_γ =
  /// `uncalibrated_gamma_sigma_m` when that is > 0 (uwb.uncalibrated_gamma_sigma_m: its γ is
  /// unknown, not zero), so that a fixed γ inflates the range noise by it.
  UwbNetwork(const SystemSetup& setup, double fallback_sigma_m, double uncalibrated_gamma_sigma_m = 0.0);

  bool isTag(SensorId id) const { return tags_p_TinI_.count(id) > 0; }
  const Eigen::Vector3d* tagLeverArm(SensorId id) const;
  const Eigen::Vector3d* exactAnchor(SensorId id) const;
  const std::map<SensorId, Eigen::Vector3d>& tags() const { return tags_p_TinI_; }
  const std::map<SensorId, Eigen::Vector3d>& exactAnchors() const { return exact_anchors_p_AinG_; }

  /// Bias of the pair (either order): the dictionary entry or γ = 0, β = 1 (σ then from
  /// `rangeSigma`'s fallbacks).
  PairBias pairBias(SensorId a, SensorId b) const;
  bool hasPairBias(SensorId a, SensorId b) const { return biases_.count(pairKey(a, b)) > 0; }
  /// Inserts or replaces the pair's bias.
  void setPairBias(const PairBias& b) { biases_[pairKey(b.a, b.b)] = b; }
  /// Inserts or moves an exactly known anchor (a fleet's peer tag for one update: EstimatorNode::processPeerRange).
  void setExactAnchor(SensorId id, const Eigen::Vector3d& p_AinG) { exact_anchors_p_AinG_[id] = p_AinG; }
  /// Forgets a tag or an exactly known anchor (its ranges become unknown). False if absent.
  bool removeDevice(SensorId id) { return tags_p_TinI_.erase(id) + exact_anchors_p_AinG_.erase(id) > 0; }
  /// Anchors that came from a calibration (ANCHOR_INIT), until removed.
  void setCalibrated(SensorId id, bool calibrated) {
    if (calibrated)
      calibrated_.insert(id);
    else
      calibrated_.erase(id);
  }
  bool isCalibrated(SensorId id) const { return calibrated_.count(id) > 0; }
  /// Range σ [m]: the pair's σ if the pair is in the dictionary, else setup.noise.sigma_range,
  /// else √R of the range when R > 0, else the config fallback.
  double rangeSigma(SensorId a, SensorId b, double R_m2) const;
  /// The UWB stamps' delay against the IMU clock from setup.yaml `uwb_clock.offset_s` [s]: the
  /// range model's constant while the offset is not a state (ClockOffsetKind).
  double clockOffsetPrior_s() const { return clock_offset_s_; }

 private:
  std::map<SensorId, Eigen::Vector3d> tags_p_TinI_;
  std::map<SensorId, Eigen::Vector3d> exact_anchors_p_AinG_;
  std::map<std::pair<SensorId, SensorId>, PairBias> biases_;
  std::set<SensorId> calibrated_;
  std::optional<double> setup_sigma_m_;
  double fallback_sigma_m_ = 0.15;
  double clock_offset_s_ = 0.0;
};

}  // namespace meshnav::estimator
