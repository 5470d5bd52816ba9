#pragma once
/// @file calibrator_options.h
/// @brief Tuning of the anchor calibration (paper §III-C). Loads from YAML, prints itself.
///
/// YAML layout (the one rule of common/yaml_options.h: every key optional, an unknown key or a bad
/// value is an error naming the file and the key). Files are loaded by CalibratorConfig::load
/// (calibrator/node/calibrator_config.h), the one loader of config/calibrator.yaml:
/// @code
/// calibrator:
///   sigma_range: 0.1            # σ_d [m]; default: setup.yaml noise.sigma_range, else 0.1
///   min_measurements: 30
///   ...
/// @endcode

#include <cstdint>
#include <string>

namespace YAML { class Node; }

namespace meshnav::calib {

/// Robust loss of the nonlinear refinement (applied to whitened residuals).
enum class RobustLoss { None, Huber, Cauchy };
const char* toString(RobustLoss l);
RobustLoss robustLossFromString(const std::string& s);  ///< "none" | "huber" | "cauchy"; throws otherwise

struct CalibratorOptions {
  // --- measurement model ------------------------------------------------------------------
  double sigma_range_m = 0.1;          ///< range noise σ_d [m]
  double gamma_prior_sigma_m = 0.25;   ///< prior σ of every pair's γ (|γ| ≲ 0.5 m); <= 0: none [m]
  double beta_prior_sigma = 0.005;     ///< prior σ of β around 1 (SDS-TWR: |β−1| ≲ 1 %); <= 0: none [-]
  bool estimate_beta = true;           ///< estimate β where observable (moving reference with range spread)
  double beta_min_range_spread_m = 1.0;///< std of a reference's ranges below which β is kept fixed [m]
  double moving_min_spread_m = 0.3;    ///< RMS spread of a reference's positions above which it "moves" [m]

  // --- linear step (optimal double) --------------------------------------------------------
  bool linear_bias_correction = true;  ///< second pass with predicted-distance regressor (unbiased)
  int linear_passes = 2;               ///< number of predicted-regressor passes after the first

  // --- refinement (Levenberg–Marquardt, Ceres) ---------------------------------------------
  RobustLoss robust_loss = RobustLoss::Cauchy;
  double robust_loss_scale = 2.5;      ///< loss scale in units of the whitened residual [σ]
  int lm_max_iterations = 50;

  // --- RANSAC ------------------------------------------------------------------------------
  bool ransac = true;
  uint64_t ransac_seed = 1;            ///< sampling is deterministic for a fixed seed (and anchor id)
  double ransac_threshold_sigmas = 3.0;///< inlier if |z − ẑ| < k·(σ_d + σ_p) (paper: k = 1)
  double ransac_confidence = 0.99;     ///< probability of drawing one outlier-free sample
  int ransac_min_iterations = 20;
  int ransac_max_iterations = 500;
  int ransac_rows_margin = 2;          ///< sample gives (unknowns + margin) difference rows

  // --- covariance --------------------------------------------------------------------------
  bool scale_covariance_by_residuals = true;  ///< multiply by s² when s² > 1
  /// Share c ∈ [0, 1] of the moving references' position covariance treated as an error common to
  /// all of them (an estimated trajectory's error is correlated over the collection window, so it
  /// does not average out): Σ_x += c·S Σ̄_R Sᵀ with S = ∂x̂/∂δ of a common shift δ. 0 = independent.
  double correlated_reference_fraction = 1.0;
  double outlier_threshold_sigmas = 3.0;      ///< final inlier test |r| < k·σ_eff·max(1, s_robust)

  // --- refusals ----------------------------------------------------------------------------
  int min_measurements = 30;                 ///< fewer ranges to the anchor → refuse
  int min_measurements_per_reference = 5;    ///< a reference with fewer ranges is ignored
  int min_distinct_positions = 10;           ///< distinct moving-reference positions (on a grid)
  double distinct_position_resolution_m = 0.1;
  double min_plane_spread_m = 0.15;  ///< RMS distance of moving references from their best plane
  double min_line_spread_m = 0.3;    ///< RMS distance of moving references from their best line
  double max_position_sigma_m = 3.0; ///< larger 1σ (largest axis) → ill-conditioned, refuse
  /// Coplanar moving references (a walk, a level flight) leave the anchor's side of their plane
  /// open. A stationary reference (a known or calibrated anchor ranging to it) at least this far
  /// off that plane can tell the side: the anchor is then fitted on both sides and the better fit
  /// kept (`mirror_min_cost_gap`). ≤ 0: coplanar references are refused as before [m].
  double mirror_reference_min_offset_m = 0.5;
  /// ...only while the moving references lie this close to their plane (RMS): a plane that well
  /// defined is the one the mirror image is taken across. Between this and `min_plane_spread_m`
  /// (automatic mode asks 0.5 m) the references are refused (waited for) as before: e.g. a take-off
  /// and a level flight tilt the best plane, and its mirror image is not the ambiguity [m].
  double mirror_max_plane_spread_m = 0.15;
  /// A side-decided anchor whose σ along the plane's normal exceeds this is refused (waited for):
  /// seen from coplanar references its distance from the plane enters the ranges to second order
  /// only, and a weakly fixed one was found 2.8σ off on a sweep run (seed-4 run067) [m].
  double mirror_max_normal_sigma_m = 0.15;
  /// The worse side's robust cost (Ceres, ½ Σ ρ) must exceed the better one's by this much, else
  /// the calibration is refused as mirror-ambiguous [-].
  double mirror_min_cost_gap = 10.0;
  /// Undecided sides at most this far apart (an anchor near the plane) are not refused: the better
  /// one is kept with its variance along the normal widened by their distance squared. Off (0) by
  /// default: the filter's refinement of such an anchor from the same coplanar tags turned
  /// overconfident on the random walks (docs/calibration.md) [m].
  double mirror_merge_max_m = 0.0;

  // --- observation building ----------------------------------------------------------------
  bool use_range_variance = false;   ///< use the range's own R [m²] as σ_d² when > 0
  double max_pose_gap_s = 0.5;       ///< pose interpolation: bracketing samples at most this apart
  double min_tag_position_sigma_m = 0.0;  ///< floor on a tag position σ (e.g. for estimated poses)

  /// Reads the keys present under `node` (the `calibrator:` map). Throws std::runtime_error naming
  /// `where` and the key on an unknown key or a value of the wrong type/range.
  static CalibratorOptions fromYaml(const YAML::Node& node, const std::string& where);
  /// Throws std::runtime_error naming the key of a value out of range.
  void validate() const;
  /// Multi-line "key: value" listing.
  std::string toString() const;
};

}  // namespace meshnav::calib
