#pragma once
/// @file synthetic_scenario.h
/// @brief A small analytic scenario (not the paper simulator) for the estimator's unit tests and
/// benchmarks: smooth trajectory with a landed phase, exact IMU/baro/range samples, optional noise.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

#include "common/dataset.h"

namespace meshnav::estimator::synthetic {

struct SyntheticOptions {
  double duration_s = 20.0;
  double landed_s = 3.0;          ///< stationary, landed at the start [s]
  double imu_rate_hz = 200.0;
  double baro_rate_hz = 20.0;
  double pair_rate_hz = 1.0;      ///< per ordered (initiator, responder) pair [Hz]
  int n_estimated_anchors = 0;    ///< extra anchors (106, 107, …) given with a σ in setup (estimated)
  double estimated_anchor_sigma_m = 0.1;
  bool anchor_to_anchor = true;   ///< also range between anchors
  bool with_initial_pose = true;
  bool noise = false;             ///< add sensor noise (else exact samples)
  uint32_t seed = 1;
  double sigma_range_m = 0.1;
  double acc_noise_density = 0.01;
  double gyro_noise_density = 0.001;
  double baro_sigma_pa = 1.0;
  Eigen::Vector3d bias_acc_m_s2 = Eigen::Vector3d::Zero();   ///< constant IMU biases in the data
  Eigen::Vector3d bias_gyro_rad_s = Eigen::Vector3d::Zero();
  double yaw0_deg = 30.0;
};

/// Analytic trajectory (position, orientation) and its derivatives.
class SyntheticTrajectory {
 public:
  explicit SyntheticTrajectory(double landed_s, double yaw0_rad) : landed_s_(landed_s), yaw0_(yaw0_rad) {}
  Eigen::Vector3d position(double t) const;
  Eigen::Matrix3d rotation(double t) const;  ///< R_ItoG
  Eigen::Vector3d velocity(double t) const;
  Eigen::Vector3d accelerationG(double t) const;
  Eigen::Vector3d angularVelocityI(double t) const;
  /// Noise-free IMU reading (gravity g_G = [0, 0, −g]).
  ImuSample imu(double t, double gravity_m_s2 = 9.81) const;

 private:
  double landed_s_, yaw0_;
};

/// The setup shared by every synthetic dataset (tags 100/105, exact anchors 101–104, IMU 1, baro 2).
SystemSetup syntheticSetup(const SyntheticOptions& o);
/// Dataset (with ground truth at the IMU rate) and the setup.
Dataset makeSyntheticDataset(const SyntheticOptions& o);
/// True anchor positions used by the scenario (101–104 and the estimated ones).
std::map<SensorId, Eigen::Vector3d> syntheticAnchors(int n_estimated);

}  // namespace meshnav::estimator::synthetic
