#pragma once
/// @file setup.h
/// @brief `setup.yaml` (what the system may know) and `truth.yaml` (evaluation only), docs/formats.md.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/types.h"

namespace meshnav {

/// Take-off pad prior.
struct InitialPose {
  Eigen::Vector3d p_IinG = Eigen::Vector3d::Zero();  ///< [m]
  double yaw_deg = 0.0;                              ///< yaw of I in G [deg]
  double sigma_p_m = 0.1;                            ///< [m]
  double sigma_yaw_deg = 5.0;                        ///< [deg]
};

/// A hand-held rig carried at a roughly constant height above the floor (z = 0 of G): what its user
/// knows about the height when there is no barometer or height sensor (docs/formats.md).
struct CarriedHeight {
  double height_m = 1.2;  ///< usual height of the IMU above the floor [m]
  double sigma_m = 0.3;   ///< how far the actual carrying height may be from height_m (1σ) [m]
};

/// The space the vehicle flies in: an axis-aligned box in G that the user knows (the hall, a
/// geofence) [m]. The estimator uses it only to tell a position from its mirror image across the
/// plane of coplanar known anchors (docs/robustness.md, "The flight volume").
struct FlightVolume {
  Eigen::Vector3d min_m = Eigen::Vector3d::Zero();  ///< lower corner in G [m]
  Eigen::Vector3d max_m = Eigen::Vector3d::Zero();  ///< upper corner in G [m]
  /// Distance of p outside the box (0 inside) [m].
  double distanceOutside(const Eigen::Vector3d& p) const {
    return (p - p.cwiseMax(min_m).cwiseMin(max_m)).norm();
  }
};

/// Optional noise figures overriding the tuning defaults.
struct NoiseFigures {
  std::optional<double> sigma_range_m;
  /// 1σ of the constant bias γ of a tag–anchor pair that `pair_biases` does not list, around its
  /// hardware's common offset [m] (overrides uwb.uncalibrated_gamma_sigma_m). 0: ranges whose
  /// antenna delays and biases were calibrated before they reached the file (γ = 0 exact).
  std::optional<double> sigma_gamma_m;
  /// Correlation time of a pair's range error (γ removed) [s] (overrides
  /// uwb.range_error_correlation_s). 0: independent errors, as a simulator that draws them so.
  std::optional<double> range_correlation_time_s;
  std::optional<double> imu_acc_noise_density;   ///< [m/s²/√Hz]
  std::optional<double> imu_gyro_noise_density;  ///< [rad/s/√Hz]
  std::optional<double> imu_acc_bias_rw;         ///< [m/s³/√Hz]
  std::optional<double> imu_gyro_bias_rw;        ///< [rad/s²/√Hz]
  /// σ of the biases at switch-on (datasheet "turn-on bias" or "bias repeatability"): the prior of
  /// the bias states at initialization, instead of init.sigma_bias_acc_m_s2 / _gyro_rad_s.
  std::optional<double> imu_acc_bias_sigma;      ///< [m/s²]
  std::optional<double> imu_gyro_bias_sigma;     ///< [rad/s]
  std::optional<double> baro_pressure_sigma_pa;  ///< [Pa]
};

/// The UWB clock against the IMU clock (setup.yaml `uwb_clock`): the UWB stamps' delay δ_u [s], a
/// range stamped t was measured at the IMU-clock instant t − δ_u.
struct UwbClock {
  double offset_s = 0.0;          ///< prior mean of δ_u [s]
  std::optional<double> sigma_s;  ///< its prior σ [s] (overrides uwb.clock_offset_sigma_s); 0: known exactly
};

/// Everything a user knows about the system before flight.
struct SystemSetup {
  SensorId imu_id = 1;
  SensorId baro_id = 2;
  SensorId height_id = 3;  ///< downward laser rangefinder (height.csv), its bias instance
  SensorId uwb_clock_id = 4;  ///< the UWB clock's offset instance (estimated when its prior σ > 0)
  UwbClock uwb_clock;
  std::map<SensorId, Eigen::Vector3d> rel_tag_positions;    ///< p_TinI: tag in IMU frame [m]
  std::map<SensorId, Eigen::Vector3d> abs_anchor_positions; ///< p_AinG: known anchors [m]
  /// Extension: position σ of known-but-uncertain anchors [m] (missing: exactly known).
  std::map<SensorId, double> abs_anchor_sigmas_m;
  std::vector<PairBias> pair_biases;  ///< a-priori calibrated pairs (missing pair: γ = 0, β = 1)
  Eigen::Vector3d baro_p_IP = Eigen::Vector3d::Zero();  ///< baro in IMU frame [m]
  std::optional<double> baro_reference_pressure_pa;      ///< null: taken on the ground at start
  Eigen::Vector3d height_p_IH = Eigen::Vector3d::Zero(); ///< rangefinder in IMU frame [m] (unknown: 0)
  std::optional<InitialPose> initial_pose;
  std::optional<CarriedHeight> carried_height;  ///< hand-held rig: its usual height
  std::optional<FlightVolume> flight_volume;    ///< the hall or geofence, when the user knows it
  NoiseFigures noise;

  bool isTag(SensorId id) const { return rel_tag_positions.count(id) > 0; }
  bool isKnownAnchor(SensorId id) const { return abs_anchor_positions.count(id) > 0; }
  /// The id of the IMU, the baro or the UWB clock, instances a run may have from its start: never
  /// an anchor's. (height_id is an instance only once heights come; the estimator refuses an anchor
  /// on it while it is one.)
  bool isSensorInstanceId(SensorId id) const { return id == imu_id || id == baro_id || id == uwb_clock_id; }
  /// Pair bias for (a, b) in either order, if given.
  std::optional<PairBias> findPairBias(SensorId a, SensorId b) const;
};

/// Simulated truth (evaluation only; never read by estimator or calibrator).
struct Truth {
  std::map<SensorId, Eigen::Vector3d> anchor_positions;  ///< all anchors [m]
  std::vector<PairBias> pair_biases;                      ///< true γ, β for every pair
  std::map<std::string, double> scalars;                  ///< anything else simulated (seed, σ_d, ...)
  /// Frame of groundtruth.csv (key `truth_frame`); empty: the world frame G of the anchors.
  std::string truth_frame;
  /// True when groundtruth.csv is not in G (key `align_required`): evaluation aligns (se3).
  bool align_required = false;
};

/// Load `setup.yaml`. Throws std::runtime_error naming the file and the key on a malformed file.
SystemSetup loadSetup(const std::string& path);
void saveSetup(const SystemSetup& setup, const std::string& path);
Truth loadTruth(const std::string& path);
void saveTruth(const Truth& truth, const std::string& path);

}  // namespace meshnav
