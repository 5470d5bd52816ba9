#pragma once
/// @file types.h
/// @brief Plain measurement and estimate structs shared by every library. They mirror the LCM
/// messages of `lcmtypes/` field by field but carry no middleware dependency.
///
/// Frames: G is the world (navigation) frame, z up, gravity -9.81 m/s² along z.
/// I is the IMU/body frame. Rotations are Hamilton quaternions; `q_ItoG` rotates a vector from I
/// into G (the TUM convention of groundtruth.csv): v_G = q_ItoG * v_I.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/time.h"

namespace meshnav {

/// Unique sensor id (> 0), as in the paper: tags 100/105, anchors 101–110, IMU 1, baro 2.
using SensorId = int32_t;

/// Kind of UWB device at either end of a range.
enum class UwbType : char { Tag = 'T', Anchor = 'A' };

/// One IMU reading. Specific force and angular rate in the IMU frame I.
struct ImuSample {
  Timestamp t;
  Eigen::Vector3d acc_m_s2 = Eigen::Vector3d::Zero();     ///< specific force in I [m/s²]
  Eigen::Vector3d gyro_rad_s = Eigen::Vector3d::Zero();   ///< angular rate of I w.r.t. G, in I [rad/s]
};

/// One barometer reading.
struct BaroSample {
  Timestamp t;
  double pressure_pa = 0.0;  ///< static pressure [Pa]
};

/// One two-way range between two UWB devices (`id_initiator` measured it).
struct RangeSample {
  Timestamp t;                          ///< instant of the range
  SensorId id_initiator = 0;            ///< UWB_ID1
  SensorId id_responder = 0;            ///< UWB_ID2
  UwbType type_initiator = UwbType::Tag;
  UwbType type_responder = UwbType::Anchor;
  double range_m = 0.0;                 ///< raw measured range [m]
  double range_corr_m = 0.0;            ///< corrected range as published (often = range_m) [m]
  double R_m2 = 0.0;                    ///< measurement variance given by the source [m²]; 0 = unknown
  bool los = true;                      ///< line of sight flag (carries no information in real data)
};

/// Downward laser rangefinder reading (dataset file height.csv): distance along the sensor's
/// beam to the floor, roughly the height above the floor when level.
struct HeightSample {
  Timestamp t;
  double range_m = 0.0;  ///< measured distance [m]
};

/// Landed / flying state from the flight controller.
struct FlightStateSample {
  Timestamp t;
  bool landed = false;
};

/// Ground-truth pose of I in G.
struct PoseSample {
  Timestamp t;
  Eigen::Vector3d p_IinG = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_ItoG = Eigen::Quaterniond::Identity();
};

/// Estimated pose with covariance. Orientation error is local: R = R̂ · Exp(δθ), δθ in I.
struct PoseEstimate {
  Timestamp t;
  Eigen::Vector3d p_IinG = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_IinG = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_ItoG = Eigen::Quaterniond::Identity();
  Eigen::Vector3d bias_gyro_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d bias_acc_m_s2 = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov_p_m2 = Eigen::Matrix3d::Zero();     ///< position covariance in G [m²]
  Eigen::Matrix3d cov_v = Eigen::Matrix3d::Zero();         ///< velocity covariance in G [m²/s²]
  Eigen::Matrix3d cov_theta_rad2 = Eigen::Matrix3d::Zero();///< orientation error covariance in I [rad²]
};

/// A range between one of this vehicle's tags and a tag of another vehicle of the fleet (issue 38,
/// docs/fleet.md "Inter-vehicle ranges"), with where the other vehicle's estimate puts its tag at
/// the range's instant: the estimator fuses it as a range to a point of that covariance.
struct PeerRange {
  Timestamp t;        ///< instant of the range (= range.t)
  RangeSample range;  ///< as measured; one end is this vehicle's tag, the other the peer's
  SensorId peer_tag = 0;                                      ///< the other vehicle's tag (an end of range)
  Eigen::Vector3d p_peer_tag_in_G = Eigen::Vector3d::Zero();  ///< its position from the peer's estimate [m]
  Eigen::Matrix3d cov_peer_tag_m2 = Eigen::Matrix3d::Zero();  ///< its covariance in G [m²]
};

/// Estimated (or given) anchor position with covariance.
struct AnchorEstimate {
  Timestamp t;
  SensorId id = 0;
  Eigen::Vector3d p_AinG = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov_p_m2 = Eigen::Matrix3d::Zero();
};

/// Pairwise range bias model z = beta·d + gamma + noise (paper eq. z_kl), symmetric in (a, b).
struct PairBias {
  SensorId a = 0;
  SensorId b = 0;
  double gamma_m = 0.0;       ///< constant bias γ [m]
  double beta = 1.0;          ///< distance-dependent scale β [-]
  double sigma_m = 0.1;       ///< range noise σ for this pair [m]
  double sigma_gamma_m = 0.0; ///< uncertainty of γ [m] (0: treated as exact)
  double sigma_beta = 0.0;    ///< uncertainty of β [-] (0: treated as exact)
};

/// Key of an unordered pair (smaller id first).
inline std::pair<SensorId, SensorId> pairKey(SensorId a, SensorId b) {
  return a < b ? std::make_pair(a, b) : std::make_pair(b, a);
}

/// Result of an anchor calibration, handed to the estimator (ANCHOR_INIT; docs/formats.md, calibration results).
struct AnchorInit {
  Timestamp t;                              ///< time of the calibration
  SensorId id = 0;
  Eigen::Vector3d p_AinG = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov_p_m2 = Eigen::Matrix3d::Identity();
  std::vector<PairBias> biases;             ///< one per reference device (a = reference, b = id)
  int n_inliers = 0;
  int n_outliers = 0;
  /// The calibration's joint covariance of p_AinG and the γ of `biases` (optional; both empty when
  /// not given: the γ are then independent of the position with σ = sigma_gamma_m):
  /// row i of `cov_gamma_p_m2` (n × 3) is cov(γ_i, p_AinG) [m²], `cov_gamma_m2` (n × n) the
  /// covariance among the γ in `biases` order [m²] (its diagonal: sigma_gamma_m²).
  Eigen::MatrixXd cov_gamma_p_m2;
  Eigen::MatrixXd cov_gamma_m2;

  bool hasJointCovariance() const { return cov_gamma_m2.size() > 0; }
  /// [p_AinG, γ_1..γ_n] covariance ((3 + n)², symmetrized): the joint one when given, else
  /// block-diagonal from cov_p_m2 and the sigma_gamma_m².
  Eigen::MatrixXd jointCovariance() const {
    const auto n = static_cast<Eigen::Index>(biases.size());
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(3 + n, 3 + n);
    J.topLeftCorner<3, 3>() = cov_p_m2;
    if (hasJointCovariance()) {
      J.bottomLeftCorner(n, 3) = cov_gamma_p_m2;
      J.topRightCorner(3, n) = cov_gamma_p_m2.transpose();
      J.bottomRightCorner(n, n) = cov_gamma_m2;
    } else {
      for (Eigen::Index i = 0; i < n; ++i)
        J(3 + i, 3 + i) = biases[static_cast<size_t>(i)].sigma_gamma_m * biases[static_cast<size_t>(i)].sigma_gamma_m;
    }
    return 0.5 * (J + J.transpose());
  }
  /// Empty when no joint covariance is given or its sizes fit `biases`; else what is wrong.
  std::string jointCovarianceError() const {
    const auto n = static_cast<Eigen::Index>(biases.size());
    if (cov_gamma_p_m2.size() == 0 && cov_gamma_m2.size() == 0) return "";
    if (cov_gamma_m2.rows() != n || cov_gamma_m2.cols() != n || cov_gamma_p_m2.rows() != n || cov_gamma_p_m2.cols() != 3)
      return "joint covariance sizes (" + std::to_string(cov_gamma_p_m2.rows()) + "x" +
             std::to_string(cov_gamma_p_m2.cols()) + ", " + std::to_string(cov_gamma_m2.rows()) + "x" +
             std::to_string(cov_gamma_m2.cols()) + ") do not fit " + std::to_string(n) + " biases";
    if (!cov_gamma_p_m2.allFinite() || !cov_gamma_m2.allFinite()) return "joint covariance not finite";
    return "";
  }
};

}  // namespace meshnav
