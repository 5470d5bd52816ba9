#pragma once
/// @file calibration_types.h
/// @brief Plain data of the anchor calibration (paper §III-C): one observation per range between
/// the unknown anchor x and a reference device, the per-reference bias estimates and the result.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "common/time.h"
#include "common/types.h"

namespace meshnav::calib {

/// One range z between the unknown anchor x and a reference device R whose position p_RinG at the
/// range time is known with covariance `cov_p_RinG_m2` (a tag: interpolated pose + lever arm; a
/// known anchor: its surveyed position). Model: z = β_R·‖p_AinG − p_RinG‖ + γ_R + ν, ν ~ N(0, σ_d²).
struct CalibObservation {
  Timestamp t;
  SensorId ref_id = 0;
  double z_m = 0.0;                                            ///< measured range [m]
  Eigen::Vector3d p_RinG = Eigen::Vector3d::Zero();            ///< reference position in G [m]
  Eigen::Matrix3d cov_p_RinG_m2 = Eigen::Matrix3d::Zero();     ///< its covariance [m²]
  double sigma_d_m = 0.1;                                      ///< range noise σ_d [m]
};

/// Prior belief on the pair biases between a reference device and the unknown anchor.
struct ReferencePrior {
  SensorId ref_id = 0;
  double gamma_m = 0.0;        ///< prior mean of γ [m]
  double sigma_gamma_m = 0.25; ///< prior σ of γ [m]; <= 0: no prior
  double beta = 1.0;           ///< prior mean of β [-]
  double sigma_beta = 0.005;   ///< prior σ of β [-]; <= 0: no prior
};

/// Why a calibration produced no estimate.
enum class CalibrationStatus {
  Ok,
  TooFewMeasurements,
  TooFewReferencePositions,
  DegenerateGeometry,
  IllConditioned,
};

/// Short name ("ok", "too_few_measurements", ...).
const char* toString(CalibrationStatus s);

/// Estimated biases of one pair (reference R, anchor x).
struct ReferenceBiasEstimate {
  SensorId ref_id = 0;
  bool moving = false;          ///< R moved (a tag): its ranges carry geometry
  bool beta_estimated = false;  ///< β was a free parameter (else fixed to its prior mean)
  double gamma_m = 0.0;
  double sigma_gamma_m = 0.0;
  double beta = 1.0;
  double sigma_beta = 0.0;
  double sigma_range_m = 0.0;   ///< effective range noise of this pair (model σ scaled by residuals) [m]
  int n_inliers = 0;
  int n_outliers = 0;
};

/// Result of calibrating one anchor. When `status != Ok` only `anchor_id`, `status`, `reason` and
/// the counts are meaningful: a refused calibration never carries an estimate.
struct CalibrationResult {
  SensorId anchor_id = 0;
  Timestamp t;
  CalibrationStatus status = CalibrationStatus::TooFewMeasurements;
  std::string reason;
  bool ok() const { return status == CalibrationStatus::Ok; }

  Eigen::Vector3d p_AinG = Eigen::Vector3d::Zero();          ///< refined position [m]
  Eigen::Matrix3d cov_p_m2 = Eigen::Matrix3d::Zero();        ///< its covariance [m²]
  Eigen::Vector3d p_AinG_linear = Eigen::Vector3d::Zero();   ///< linear (optimal double) solution [m]
  std::vector<ReferenceBiasEstimate> references;             ///< sorted by ref_id
  /// Joint covariance of [p_AinG, γ of references[0..n-1]] ((3 + n)², the marginal of the stacked
  /// covariance over [p, γ, β]; β marginalized out) [m²]. The γ are correlated with the position
  /// (a range to a reference fixes only their combination), which the estimator keeps (issue 10).
  Eigen::MatrixXd cov_p_gamma_m2;
  std::vector<bool> inliers;                                 ///< per input observation
  int n_observations = 0;
  int n_inliers = 0;
  int n_outliers = 0;
  int ransac_iterations = 0;
  int lm_iterations = 0;
  double residual_variance_factor = 1.0;  ///< s² = whitened residual variance (applied when > 1)

  /// The estimator's view (ANCHOR_INIT): biases as PairBias{a = reference, b = anchor}.
  AnchorInit toAnchorInit() const;
};

}  // namespace meshnav::calib
