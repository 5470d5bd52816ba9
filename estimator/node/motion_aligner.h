#pragma once
/// @file motion_aligner.h
/// @brief In-motion alignment: the full IMU pose from UWB ranges and strapdown increments over a
/// short sliding window, without a landed phase and without a prior (handheld start, in-air
/// restart, recovery after the filter was lost). Derivation in docs/robustness.md.
///
/// Over the window [t₀, t₀ + T] the gyro gives the relative attitude C(τ) = R₀ᵀ R(τ) (bias b̂_ω
/// removed) and the accelerometer the body-frame increments
///   V(τ) = ∫₀^τ C f ds,  S(τ) = ∫₀^τ V ds,  N(τ) = ∫₀^τ C ds,  M(τ) = ∫₀^τ N ds,
/// with their first-order sensitivities to a gyro bias correction δb_ω (C ≈ Ĉ Exp(J_C δb_ω),
/// S ≈ Ŝ + J_S δb_ω; a gyro bias of 0.005 rad/s tilts gravity into ~4 m over 8 s, so it must be
/// estimated). With the unknowns x = [p₀, v₀, δθ, b_a, δb_ω] (R₀ = R̂₀ Exp(δθ)) the tag T is at
///   p_T(τ) = p₀ + v₀ τ + ½ g τ² + R₀ (S(τ) − M(τ) b_a) + R₀ C(τ) p_TinI,
/// and each bias-corrected range d to a known anchor A gives the residual d − ‖p_A − p_T(τ)‖.
/// Gravity fixes roll and pitch, horizontal accelerations fix yaw, the ranges fix p₀ and v₀.
/// Gauss–Newton with Huber weights from a grid of yaw starts (and the mirror image of the start
/// position when the anchors are nearly coplanar); a second local minimum within
/// `ambiguity_chi2` × v of the best one makes the window ambiguous (refused), v = max(1,
/// (1.4826 median|e|)²) the robust variance factor of the normalized residuals. The covariance is (Jᵀ W J + prior)⁻¹ inflated by `cov_inflation`, carried to the window's end by the numeric
/// Jacobian of the end state. Refused (with a reason) while the geometry or the motion cannot
/// fix the pose: too few ranges or anchors, σ_yaw or σ_p above their limits, ambiguity.

#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/types.h"
#include "estimator/core/imu_state.h"

namespace meshnav::estimator {

/// One tag–anchor range for the alignment: anchor position and bias-corrected distance.
struct AlignRange {
  Timestamp t;
  SensorId tag = 0;
  SensorId anchor = 0;
  Eigen::Vector3d p_AinG = Eigen::Vector3d::Zero();  ///< anchor position [m]
  double d_m = 0.0;                                  ///< (z − γ)/β [m]
  double sigma_m = 0.1;                              ///< range noise σ [m]
};

struct MotionAlignerOptions {
  double window_s = 12.0;             ///< data kept and fitted [s]
  double min_span_s = 3.0;           ///< shortest window worth a fit [s]
  int min_ranges = 20;               ///< ranges needed in the window
  int min_anchors = 3;               ///< distinct anchors needed in the window
  /// Refuse while yaw is less certain [deg]. The fit's covariance is honest up to here (tested);
  /// the estimator node asks for less (init.motion_max_sigma_yaw_deg, 15°) because its filter
  /// does not pull a large heading error back.
  double max_sigma_yaw_deg = 25.0;
  double max_sigma_p_m = 0.5;        ///< refuse while the position is less certain [m]
  double sigma_bias_acc_m_s2 = 0.2;  ///< prior σ of the accelerometer bias [m/s²]
  double outlier_m = 0.6;            ///< residual beyond max(this, 4σ) is dropped [m]
  double ambiguity_chi2 = 16.0;      ///< cost margin a second minimum must exceed [-]
  double cov_inflation = 2.0;        ///< multiplies the fitted covariance (unmodelled gyro bias, timing) [-]
  double gravity_m_s2 = 9.81;        ///< |g| [m/s²]
  int yaw_starts = 12;               ///< yaw grid of the multi-start [-]
  double sigma_bias_gyro_rad_s = 0.005;  ///< σ of the gyro bias in the result [rad/s]
  double max_imu_gap_s = 0.1;        ///< increments cannot span a longer IMU gap: the window restarts [s]
};

/// The aligned state at the window's end.
struct AlignmentResult {
  Timestamp t;
  ImuState imu;
  ImuMatrix cov = ImuMatrix::Identity();
  int n_ranges = 0;          ///< ranges used (inliers)
  int n_anchors = 0;         ///< distinct anchors among them
  double rms_m = 0.0;        ///< RMS residual of the inliers [m]
  double sigma_p_m = 0.0;    ///< largest position σ at the end [m]
  double sigma_yaw_deg = 0.0;
  ImuSample last_imu;        ///< the IMU reading at `t`
};

class MotionAligner {
 public:
  MotionAligner(const MotionAlignerOptions& options, std::map<SensorId, Eigen::Vector3d> tags_p_TinI);

  void addImu(const ImuSample& s);
  void addRange(const AlignRange& r);
  void clear();
  /// Fits the current window; nullopt (see `reason()`) while the pose is not determined.
  std::optional<AlignmentResult> solve(const Eigen::Vector3d& bias_gyro_rad_s);
  /// Why the last `solve` refused.
  const std::string& reason() const { return reason_; }
  /// Data span currently held [s].
  double spanSeconds() const;
  const MotionAlignerOptions& options() const { return options_; }

  /// Strapdown increments at one instant relative to the window start (see the file comment).
  struct Increments {
    Eigen::Matrix3d C = Eigen::Matrix3d::Identity();
    Eigen::Vector3d V = Eigen::Vector3d::Zero(), S = Eigen::Vector3d::Zero();
    Eigen::Matrix3d N = Eigen::Matrix3d::Zero(), M = Eigen::Matrix3d::Zero();
    /// ∂(Log C, V, S)/∂b_ω: δφ_C = J_C δb_ω, δV = J_V δb_ω, δS = J_S δb_ω.
    Eigen::Matrix3d JC = Eigen::Matrix3d::Zero(), JV = Eigen::Matrix3d::Zero(), JS = Eigen::Matrix3d::Zero();
    double tau_s = 0.0;
  };
  /// The unknowns of the fit.
  struct Unknowns {
    Eigen::Vector3d p0 = Eigen::Vector3d::Zero(), v0 = Eigen::Vector3d::Zero();
    Eigen::Matrix3d R0 = Eigen::Matrix3d::Identity();
    Eigen::Vector3d ba = Eigen::Vector3d::Zero();
    Eigen::Vector3d dbg = Eigen::Vector3d::Zero();  ///< gyro bias correction to b̂_ω [rad/s]
    /// x ⊞ δ with δ = [δp₀, δv₀, δθ, δb_a, δb_ω].
    Unknowns plus(const Eigen::Matrix<double, 15, 1>& d) const;
  };

 private:
  struct Obs {
    AlignRange r;
    Increments inc;
    bool use = true;
  };
  std::vector<Obs> buildObservations(const Eigen::Vector3d& bias_gyro, Increments* end) const;
  /// Levenberg–Marquardt with Huber weights; returns the cost (Huber terms and bias priors).
  double fit(const std::vector<Obs>& obs, Unknowns& x, Eigen::Matrix<double, 15, 15>* info) const;
  /// max(1, (1.4826 · median|e_i|)²) over the inliers: how much noisier than their σ the ranges fit.
  double robustVarianceFactor(const std::vector<Obs>& obs, const Unknowns& x) const;
  double residual(const Obs& o, const Unknowns& x) const;
  /// ∂residual/∂[δp₀, δv₀, δθ, δb_a, δb_ω] (analytic; the noise-free unit test converges with it).
  Eigen::Matrix<double, 1, 15> jacobian(const Obs& o, const Unknowns& x) const;
  /// Tag position (τ of `inc`) and the body-frame vector w it is R₀ w away from the
  /// gravity/velocity terms.
  Eigen::Vector3d bodyTerm(const Increments& inc, const Unknowns& x, const Eigen::Vector3d& p_TinI) const;
  ImuState endState(const Unknowns& x, const Increments& end, const Eigen::Vector3d& bias_gyro) const;
  std::vector<Unknowns> starts(const std::vector<Obs>& obs) const;
  /// Covariance, end state and the acceptance checks of the best fit.
  std::optional<AlignmentResult> finish(const std::vector<Obs>& obs, const Unknowns& x,
                                        const Eigen::Matrix<double, 15, 15>& info, const Increments& end,
                                        const Eigen::Vector3d& bias_gyro);

  MotionAlignerOptions options_;
  std::map<SensorId, Eigen::Vector3d> tags_p_TinI_;
  std::deque<ImuSample> imu_;
  std::deque<AlignRange> ranges_;
  std::string reason_ = "no data";
};

}  // namespace meshnav::estimator
