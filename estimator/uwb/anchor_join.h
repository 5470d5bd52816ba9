#pragma once
/// @file anchor_join.h
/// @brief A calibrated anchor joins the filter (ANCHOR_INIT, ESTIMATOR_CMD add-anchor;
/// docs/modular_estimator.md "Anchor join").
///
/// The anchor becomes an estimated instance: its position p_AinG and, with
/// `uwb.estimate_anchor_biases`, the pair biases γ it has with an uncertainty (σ_γ > 0) as states
/// after it, with the calibration's joint covariance of [p, γ_1..γ_n] (`uwb.anchor_bias_joint_covariance`;
/// else the marginals): a γ error and the position error along that reference's direction are
/// strongly correlated, and fixing γ would let repeated ranges average away a constant error. The
/// network learns its pair biases and that it is calibrated; an exactly known anchor of the same
/// id becomes an estimated one.
///
/// With DAH (`uwb.dah_joint_anchors`), the anchors added at one filter time (a batch: calibrated
/// together) form a joint set, with every calibrated anchor for "all", the tags' γ
/// (`uwb.dah_joint_tag_biases`) and the IMU with its vertical aids' biases (`uwb.dah_joint_imu`),
/// bounded to `uwb.dah_joint_max_anchors` anchors (boundJointSetAnchors).

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/diagnostics.h"
#include "common/setup.h"
#include "estimator/core/estimator_options.h"
#include "estimator/filter/fusion_strategy.h"
#include "estimator/uwb/uwb_network.h"

namespace meshnav::estimator {

class AnchorJoin {
 public:
  /// `dah`: the strategy is DAH (joint sets); `setup` and `diag` must outlive this object.
  AnchorJoin(const UwbOptions& options, bool dah, const SystemSetup& setup, Diagnostics& diag);
  /// Adds anchor `a` to `f` and `network` (replaced by a copy that knows it); "" when done (counted
  /// "anchor_init" and logged when `log`), else why not (its id is a tag's or a sensor's instance).
  std::string apply(const AnchorInit& a, FusionStrategy& f, std::shared_ptr<const UwbNetwork>& network, bool log);
  /// Anchors that come before the pose (ANCHOR_INIT, an add command, a restart's kept anchors) are
  /// held and applied at the initialization; a reset does not drop them.
  void hold(const AnchorInit& a) { held_.push_back(a); }
  std::vector<AnchorInit>& held() { return held_; }
  std::vector<AnchorInit> takeHeld() { return std::exchange(held_, {}); }

 private:
  /// DAH: puts the just added anchor `id` into its joint set.
  void joinSet(SensorId id, FusionStrategy& f, const UwbNetwork& network);

  UwbOptions options_;
  bool dah_;
  const SystemSetup& setup_;
  Diagnostics& diag_;
  std::vector<SensorId> batch_;      ///< the anchors added at the filter time `batch_t_`
  std::optional<Timestamp> batch_t_;
  std::vector<AnchorInit> held_;
};

}  // namespace meshnav::estimator
