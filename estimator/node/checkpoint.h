#pragma once
/// @file checkpoint.h
/// @brief What an estimator needs to resume after a restart without re-initializing: the IMU
/// state with its covariance, the barometer's reference and bias, and every estimated anchor with
/// its pair biases (docs/robustness.md, "Restarts").
///
/// A restarted estimator process reads the checkpoint its predecessor wrote (`--state-dir`) and,
/// when the first IMU sample is at most `init.resume_max_age_s` newer, starts from it at once:
/// the position moved by v·Δt and the covariance grown by the IMU-gap noise over Δt (velocity
/// random walk `imu.gap_sigma_acc_m_s2`, position its integral; attitude by the gyro density).
/// Cross-covariances between the IMU and the anchors are not kept (marginals only), as in a
/// recovery; tag γ states start again from the setup's a-priori values.
///
/// Files in the state folder (written atomically: a temporary file, then rename):
///   estimator_state.yaml   t [s], p_IinG [m], v_IinG [m/s], q_ItoG [x, y, z, w],
///                          bias_gyro_rad_s, bias_acc_m_s2, cov_imu (15×15 row-major, error state
///                          δp, δv, δθ, δb_ω, δb_a), landed, baro_reference_pa (null: none),
///                          baro_bias_m, baro_bias_var_m2
///   estimator_anchors.yaml the calibration results format (common/anchor_init_io.h)

#include <optional>
#include <string>
#include <vector>

#include "common/time.h"
#include "common/types.h"
#include "estimator/core/imu_state.h"

namespace meshnav::estimator {

struct EstimatorCheckpoint {
  Timestamp t;                    ///< the instant the state is valid at (data time)
  ImuState imu;
  ImuMatrix cov_imu = ImuMatrix::Identity();
  bool landed = false;
  std::optional<double> baro_reference_pa;
  double baro_bias_m = 0.0;
  double baro_bias_var_m2 = 1.0;
  std::vector<AnchorInit> anchors;  ///< estimated anchors: marginal covariance, pair biases
};

/// Writes the two files into `dir` (created). Throws std::runtime_error naming the file.
void writeCheckpoint(const EstimatorCheckpoint& c, const std::string& dir);
/// Reads them back; nullopt when `dir` holds no checkpoint. Throws std::runtime_error naming the
/// file and key on a malformed or non-finite one.
std::optional<EstimatorCheckpoint> readCheckpoint(const std::string& dir);

}  // namespace meshnav::estimator
