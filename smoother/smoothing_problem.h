#pragma once
/// @file smoothing_problem.h
/// @brief What the batch smoother fits: navigation states at knots tied by preintegrated IMU
/// increments, tag–anchor ranges between knots, and the range biases that are unknown. Plain
/// data, built by smoother/run_inputs.h from a dataset and a filter run (or by a test).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "common/types.h"
#include "smoother/imu_preintegration.h"

namespace meshnav::smoother {

/// The navigation state of I at one instant.
struct NavState {
  Timestamp t;
  Eigen::Vector3d p_IinG = Eigen::Vector3d::Zero();           ///< [m]
  Eigen::Vector3d v_IinG = Eigen::Vector3d::Zero();           ///< [m/s]
  Eigen::Quaterniond q_ItoG = Eigen::Quaterniond::Identity();
  Eigen::Vector3d bias_gyro_rad_s = Eigen::Vector3d::Zero();  ///< b_ω [rad/s]
  Eigen::Vector3d bias_acc_m_s2 = Eigen::Vector3d::Zero();    ///< b_a [m/s²]
};

/// A Gaussian prior on the first knot's pose (the filter's belief from the data before it).
struct PosePrior {
  Eigen::Vector3d p_IinG = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_ItoG = Eigen::Quaterniond::Identity();
  Eigen::Matrix3d cov_p_m2 = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d cov_theta_rad2 = Eigen::Matrix3d::Identity();  ///< local error, R = R̂ Exp(δθ)
};

/// An unknown constant of the range model, with its Gaussian prior.
struct RangeBiasUnknown {
  double prior_mean_m = 0.0;
  double prior_sigma_m = 0.1;
};

/// One tag–anchor range, z = β ‖p_A − p_T(t)‖ + γ + ν, γ = γ_fixed + Σ (unknowns listed); or,
/// with `tag` 0, an anchor–anchor range z = β ‖p_A − p_B‖ + γ + ν (the mesh), which informs only
/// anchors that are unknowns of the fit.
struct SmootherRange {
  Timestamp t;                                       ///< instant of the measurement, IMU clock
  SensorId tag = 0, anchor = 0;
  SensorId anchor_b = 0;                             ///< the other anchor of an anchor–anchor range
  Eigen::Vector3d p_BinG = Eigen::Vector3d::Zero();  ///< its position (initial value when estimated) [m]
  int anchor_b_unknown = -1;                         ///< its index into `anchors`, −1: known
  Eigen::Vector3d p_TinI = Eigen::Vector3d::Zero();  ///< [m]
  Eigen::Vector3d p_AinG = Eigen::Vector3d::Zero();  ///< [m] (the initial value when `anchor_unknown` ≥ 0)
  int anchor_unknown = -1; ///< index into `anchors` when the anchor's position is estimated, −1: known
  double z_m = 0.0;                                  ///< measured range [m]
  double beta = 1.0;                                 ///< [-]
  double gamma_fixed_m = 0.0;                        ///< known part of γ [m]
  int gamma_unknown = -1;  ///< index into `range_biases` of the pair's own γ part, −1: none
  int common_unknown = -1; ///< index of the tag's common offset, −1: none
  double sigma_m = 0.15;   ///< noise σ of this range (correlation with its pair's previous one included) [m]
  /// σ_m over the range's own σ (the correlation's √((1 + ρ)/(1 − ρ))): the robust loss's scale
  /// stays at its multiple of the range's own σ [-]
  double noise_inflation = 1.0;
};

/// One downward rangefinder reading: h = (p_IinG + R p_IH)_z / c + b_H + ν, c = (R e_z)_z with
/// the tilt correction (else 1), the floor at z = 0 of G (z up), b_H one constant per problem.
struct SmootherHeight {
  Timestamp t;
  double range_m = 0.0;  ///< [m]
  double sigma_m = 0.05; ///< [m]
};

/// An anchor whose position is estimated with the trajectory (a bundle adjustment). A calibrated
/// anchor has no prior, so that no range counts twice (its calibration came from these ranges); a
/// known-but-uncertain one (setup `abs_anchor_sigmas`) has the setup's. The known anchors fix the frame.
struct AnchorUnknown {
  SensorId id = 0;
  Eigen::Vector3d p_AinG = Eigen::Vector3d::Zero();  ///< initial value [m]
  Eigen::Vector3d prior_mean_m = Eigen::Vector3d::Zero();
  double prior_sigma_m = 0.0;                        ///< per axis [m]; 0: no prior
};

struct SmoothingProblem {
  std::vector<ImuSample> imu;             ///< covers the knots' span, sorted
  std::vector<NavState> knots;            ///< initial values, strictly increasing times
  std::vector<SmootherRange> ranges;      ///< within [first knot, last knot]
  std::vector<RangeBiasUnknown> range_biases;
  std::vector<AnchorUnknown> anchors;           ///< estimated anchor positions
  std::vector<SmootherHeight> heights;          ///< within [first knot, last knot]
  Eigen::Vector3d p_IH = Eigen::Vector3d::Zero();  ///< rangefinder in I [m]
  bool height_tilt_correction = true;
  double height_bias_sigma_m = 0.3;             ///< prior σ of b_H around 0 [m]
  std::optional<PosePrior> first_pose_prior;
  /// Knots the flight state calls landed (same size as `knots`, or empty): the body rests, v = 0
  /// (σ `rest_sigma_vel_m_s`), and it does not turn between two resting knots (σ
  /// `rest_sigma_rate_rad_s` × Δt), the filter's ZUPT model (estimator zupt options).
  std::vector<bool> at_rest;
  double rest_sigma_vel_m_s = 0.02;       ///< [m/s]
  double rest_sigma_rate_rad_s = 0.001;   ///< [rad/s]
  Eigen::Vector3d gravity_G = Eigen::Vector3d(0.0, 0.0, -9.81);  ///< [m/s²]
  ImuNoiseDensities imu_noise;
  double acc_bias_rw = 0.002;             ///< [m/s³/√Hz]
  double gyro_bias_rw = 0.0002;           ///< [rad/s²/√Hz]
  double acc_bias_sigma = 0.2;            ///< prior σ of the first knot's b_a [m/s²]
  double gyro_bias_sigma = 0.01;          ///< prior σ of the first knot's b_ω [rad/s]
};

}  // namespace meshnav::smoother
