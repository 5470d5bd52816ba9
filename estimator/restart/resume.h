#pragma once
/// @file resume.h
/// @brief A restarted estimator's start from its predecessor's checkpoint (checkpoint.h,
/// docs/robustness.md "Restarts"), and the checkpoint a running one writes.
///
/// The model across an outage of Δt = t_first_imu − t_checkpoint: the position moved with the
/// velocity (Φ_pv = I Δt); what the body did meanwhile is unknown, bounded by a largest acceleration
/// a (`init.resume_max_acc_m_s2`) and rotation rate ω (`init.resume_max_rate_deg_s`):
///   P ← Φ P Φᵀ + diag((a Δt²/2)² I on p, (a Δt)² I on v, (ω Δt)² I on θ).
/// Only across an outage of at most `init.resume_max_outage_s` (beyond it the bound is too loose to
/// help and the pose is initialized anew); a checkpoint older than `init.resume_max_age_s` is not
/// used at all. Anchors, the baro reference and the kept instances (Restart::kKept) come back
/// whatever the outage, each instance's marginal covariance grown by its kind's random walk.

#include <optional>
#include <vector>

#include "common/diagnostics.h"
#include "common/setup.h"
#include "estimator/core/estimator_options.h"
#include "estimator/filter/fusion_strategy.h"
#include "estimator/init/static_initializer.h"
#include "estimator/restart/checkpoint.h"
#include "estimator/uwb/uwb_network.h"

namespace meshnav::estimator {

/// The state to persist: the IMU block and its covariance, `landed`, the baro reference, every kept
/// instance, and (`with_anchors`) every estimated anchor with its marginal covariance and pair
/// biases (their γ states and their joint covariance with the position). Without them `anchors` is
/// empty: for a checkpoint whose anchors' file is not rewritten (writeCheckpoint's `with_anchors`),
/// which saves gathering every anchor's pair biases every 0.1 s.
EstimatorCheckpoint makeCheckpoint(const FusionStrategy& f, const UwbNetwork& network, bool landed,
                                   const std::optional<double>& baro_reference_pa, const EstimatorOptions& options,
                                   bool with_anchors = true);

class Resume {
 public:
  Resume(const EstimatorOptions& options, const SystemSetup& setup, Diagnostics& diag)
      : options_(options), setup_(setup), diag_(diag) {}
  /// A checkpoint to resume from at the first IMU sample.
  void offer(EstimatorCheckpoint c) { offered_ = std::move(c); }
  bool offered() const { return offered_.has_value(); }
  /// At the first IMU sample `s`: the checkpoint's anchors go to `anchors` (applied at the
  /// initialization) and its kept instances are held for `restoreKept`; the belief to initialize
  /// with when the pose itself is resumed (outage short enough). Counted "resumed" /
  /// "resume_refused".
  std::optional<InitialBelief> at(const ImuSample& s, std::vector<AnchorInit>& anchors);
  /// The held checkpoint's baro reference (a restart in flight keeps its predecessor's).
  std::optional<double> keptBaroReference() const {
    return kept_ ? kept_->baro_reference_pa : std::nullopt;
  }
  /// Adds the held kept instances to `f` at `t`, replacing their priors (a baro bias only against
  /// the same reference pressure `baro_reference_pa`), then forgets them. Counted "resumed_instances".
  void restoreKept(FusionStrategy& f, Timestamp t, const std::optional<double>& baro_reference_pa);

 private:
  const EstimatorOptions& options_;
  const SystemSetup& setup_;
  Diagnostics& diag_;
  std::optional<EstimatorCheckpoint> offered_;  ///< until the first IMU sample
  std::optional<EstimatorCheckpoint> kept_;     ///< its baro reference and kept instances, until initialized
};

}  // namespace meshnav::estimator
