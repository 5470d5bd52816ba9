#pragma once
/// @file synthetic_scene.h
/// @brief A small self-contained generator of calibration observations (no simulator needed):
/// a UAV on the paper's upward spiral carrying tags 100/105, the known anchors 101–104 and one
/// unknown anchor, with pairwise biases, range noise, reference-position noise and outliers.
/// Used by the unit tests and the benchmark.

#include <cstdint>
#include <map>
#include <vector>

#include "calibrator/calibration_types.h"

namespace meshnav::calib {

/// Spiral: the paper's upward spiral; Planar: the same circle at a constant 2 m; Walk: that circle
/// at a hand-held 1.2 m with a gait bob of ±0.12 m (nearly coplanar); Line; Hover.
enum class SyntheticPath { Spiral, Planar, Walk, Line, Hover };

struct SyntheticSceneConfig {
  Eigen::Vector3d p_AinG{-1.772, 0.943, 3.256};  ///< true unknown anchor (paper's 106) [m]
  SyntheticPath path = SyntheticPath::Spiral;
  double duration_s = 80.0;      ///< ranges are spread over [0, duration]
  int n_ranges = 700;            ///< total over all references
  bool known_anchors = true;     ///< include ranges to 101–104
  double sigma_d_m = 0.1;        ///< true range noise
  double sigma_ref_m = 0.0;      ///< noise on the tag positions handed to the calibrator (and its σ)
  double outlier_fraction = 0.0; ///< fraction of ranges with an added NLOS error U(0.5, 3) m
  double gamma_max_m = 0.4;      ///< true γ ~ U(−max, max) per pair
  double beta_sigma = 0.0;       ///< true β ~ 1 + N(0, beta_sigma) for tag pairs
  uint64_t seed = 1;
  double model_sigma_d_m = -1.0; ///< σ_d written into the observations (< 0: the true one)
};

struct SyntheticScene {
  std::vector<CalibObservation> observations;
  Eigen::Vector3d p_AinG = Eigen::Vector3d::Zero();
  std::map<SensorId, double> gamma_m;  ///< true γ per reference
  std::map<SensorId, double> beta;     ///< true β per reference
  std::vector<bool> is_outlier;        ///< per observation
};

SyntheticScene makeSyntheticScene(const SyntheticSceneConfig& cfg);

}  // namespace meshnav::calib
