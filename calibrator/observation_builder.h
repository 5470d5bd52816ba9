#pragma once
/// @file observation_builder.h
/// @brief Turns ranges + a pose history + the system setup into calibration observations of an
/// unknown anchor x (docs/calibration.md): a tag reference sits at p_TinG = p_IinG + R_ItoG·p_TinI at the range
/// time (pose interpolated), with covariance Σ_p + R[p_TinI]ₓ Σ_θ [p_TinI]ₓᵀRᵀ (orientation error
/// local, R = R̂·Exp(δθ)); a known anchor sits at its surveyed position with σ² I.

#include <map>
#include <optional>
#include <vector>

#include "calibrator/calibration_types.h"
#include "calibrator/calibrator_options.h"
#include "common/diagnostics.h"
#include "common/setup.h"

namespace meshnav::calib {

class ObservationBuilder {
 public:
  ObservationBuilder(SystemSetup setup, const CalibratorOptions& options);

  /// Pose history with covariances (estimate.csv), any order.
  void setPoses(std::vector<PoseEstimate> poses);
  /// Pose history without covariances (ground truth / TUM), any order.
  void setPoses(const std::vector<PoseSample>& poses);

  /// Observations of anchor `x` from the ranges with t in [t_start, t_end]. References are the
  /// setup's tags and known anchors other than x (x itself may be a known anchor: it is then
  /// calibrated as if unknown). Ranges without a pose, to unknown ids or with a non-finite value
  /// are counted in `diag` ("calibrator:..."), never used.
  std::vector<CalibObservation> collect(SensorId x, const std::vector<RangeSample>& ranges, Diagnostics& diag,
                                        std::optional<Timestamp> t_start = std::nullopt,
                                        std::optional<Timestamp> t_end = std::nullopt) const;

  /// A-priori pair biases of setup.yaml that involve x (used as priors instead of the defaults).
  std::map<SensorId, ReferencePrior> priors(SensorId x) const;

  /// Position and covariance of tag `tag` at `t`; nullopt without a pose.
  std::optional<std::pair<Eigen::Vector3d, Eigen::Matrix3d>> tagPosition(SensorId tag, Timestamp t) const;

 private:
  SystemSetup setup_;
  CalibratorOptions options_;
  std::vector<PoseEstimate> poses_;
};

/// Tag position p_TinG = p_IinG + R_ItoG p_TinI at a pose and its covariance
/// Σ_T = Σ_p + (R[p_TinI]ₓ) Σ_θ (R[p_TinI]ₓ)ᵀ (local orientation error) + σ_min² I.
std::pair<Eigen::Vector3d, Eigen::Matrix3d> tagPositionAtPose(const PoseEstimate& pose, const Eigen::Vector3d& p_TinI,
                                                              double min_sigma_m);

/// The range `r` involving the unknown anchor `x` as an observation of the reference at the other
/// end: time, reference id, range and its σ_d (the range's own variance when
/// `use_range_variance` and R > 0, else `sigma_range_m`). The reference position is left to the
/// caller (tag pose, known or calibrated anchor).
CalibObservation rangeObservation(const RangeSample& r, SensorId x, const CalibratorOptions& options);

}  // namespace meshnav::calib
