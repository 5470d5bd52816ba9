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
/// `ambiguity_chi2` × v of the best one makes the window ambiguous (refused), v the robust
/// variance factor of the normalized residuals (huber::varianceFactor). The covariance is
/// (Jᵀ W J + prior)⁻¹ inflated by `cov_inflation`, carried to the window's end by the numeric
/// Jacobian of the end state. Refused (with a reason) while the geometry or the motion cannot
/// fix the pose: too few ranges or anchors, σ_yaw or σ_p above their limits, ambiguity.
///
/// Sparse ranging: while `window_s` holds fewer than `min_ranges` ranges, the window reaches back
/// until it holds them (at most `max_window_s`), so the count, not only the time, decides.
/// Heights of a downward rangefinder (optional) add the vertical constraint
///   h = (p_I(τ) + R₀C(τ) p_IH)_z / c(τ) + b_H,  c = e_zᵀ R₀ C(τ) e_z  (c ≡ 1 without tilt correction)
/// with one more unknown, the sensor's bias b_H ~ N(0, σ_bH²): the floor is at z = 0 of G, so the
/// mirror image of the trajectory across nearly coplanar anchors no longer fits.

#include <deque>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/setup.h"
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

/// One downward rangefinder reading for the alignment.
struct AlignHeight {
  Timestamp t;
  double range_m = 0.0;   ///< distance to the floor along the beam [m]
  double sigma_m = 0.05;  ///< noise σ [m]
};

struct MotionAlignerOptions {
  double window_s = 12.0;             ///< data fitted while it holds `min_ranges` ranges [s]
  double max_window_s = 40.0;         ///< sparse ranges: the window reaches back at most this far [s]
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
  /// The increments are integrated with a gyro bias b̄ and corrected to first order in δb_ω. When
  /// the best fit's |δb_ω| × window exceeds this rotation, they are integrated again at b̄ + δb_ω
  /// and fitted anew (at most `max_relinearizations` times); 0 = never [rad]
  double relinearize_rad = 0.02;
  int max_relinearizations = 3;      ///< passes of re-integration per solve [-]
  Eigen::Vector3d p_IH = Eigen::Vector3d::Zero();  ///< rangefinder in the IMU frame [m]
  bool height_tilt_correction = true;  ///< h = s_z / cos(tilt) (else s_z)
  double sigma_bias_height_m = 0.3;   ///< prior σ of the rangefinder's bias around 0 [m]
  /// The setup's flight volume: a fit that ends farther outside it than `volume_margin_m` is no
  /// candidate, neither the best nor a rival (a mirror image behind a wall of anchors).
  std::optional<FlightVolume> flight_volume;
  double volume_margin_m = 0.5;       ///< [m]
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
  int n_heights = 0;         ///< rangefinder readings used (inliers)
  double height_bias_m = 0.0;       ///< rangefinder bias b_H (prior mean 0 without heights) [m]
  double height_bias_var_m2 = 0.0;  ///< its variance [m²]
  double window_s = 0.0;     ///< span of the data fitted [s]
};

class MotionAligner {
 public:
  MotionAligner(const MotionAlignerOptions& options, std::map<SensorId, Eigen::Vector3d> tags_p_TinI);

  void addImu(const ImuSample& s);
  void addRange(const AlignRange& r);
  void addHeight(const AlignHeight& h);
  void clear();
  /// A heading the caller still knows at the window's end: a lost filter's yaw, which the gyro
  /// keeps through a range outage while the position drifts (docs/robustness.md, "Rival poses").
  struct HeadingPrior {
    double yaw_rad = 0.0;       ///< ψ of q_ItoG at the newest IMU sample [rad]
    double var_rad2 = 0.0;      ///< its variance σ_ψ² [rad²] (> 0)
  };
  /// Fits the current window; nullopt (see `reason()`) while the pose is not determined.
  /// Distinct minima that fit within the ambiguity margin are rivals. Without `heading` the window
  /// is then refused. With it each minimum k scores its negative log-posterior in the cost's units,
  /// J_k = c_k + v (ψ_k − ψ_prior)² / σ_ψ² (v the robust variance factor: the costs are v-scaled
  /// χ²), and the lowest is taken when every other scores beyond the margin; else refused. A fit
  /// without rivals is taken by its cost, as without a prior. The pose taken is then combined with
  /// the prior (finish) unless it contradicts it.
  std::optional<AlignmentResult> solve(const Eigen::Vector3d& bias_gyro_rad_s,
                                       const std::optional<HeadingPrior>& heading = std::nullopt);
  /// Which way gravity points in G, by the data. The estimator assumes −z (z up); an anchor
  /// frame whose z axis points down (ISAS-Walk1's RTLS frame, docs/real_data.md) fits the ranges
  /// and accelerations of a window better with gravity along +z. Both are fitted from the same
  /// starts on every range of the window; costs in units of the residuals' own scatter as for
  /// the ambiguity check (margin = `ambiguity_chi2` × the robust variance factor of the z-up fit).
  struct GravityCheck {
    double cost_z_up = 0.0;    ///< best cost with gravity along −z of G [-]
    double cost_z_down = 0.0;  ///< best cost with gravity along +z of G [-]
    double margin = 0.0;       ///< a difference beyond this is decisive [-]
    int n_ranges = 0;
    /// +z fits decisively better: the anchors' frame has its z axis pointing down.
    bool zDown() const { return cost_z_up - cost_z_down > margin; }
    /// −z fits decisively better (the estimator's convention holds).
    bool zUp() const { return cost_z_down - cost_z_up > margin; }
  };
  /// Compares both directions on the current window; nullopt (see `reason()`) with too little
  /// data, with heights (their floor model assumes z up) or when a fit fails.
  std::optional<GravityCheck> checkGravityDirection(const Eigen::Vector3d& bias_gyro_rad_s);
  /// From now on `solve` fits gravity along +z of G (true) or −z (false, the default).
  void setGravityAlongPlusZ(bool plus_z) { gravity_z_sign_ = assumed_gravity_z_sign_ = plus_z ? 1.0 : -1.0; }
  /// How often `solve` integrated the increments again at a corrected gyro bias (all calls).
  int relinearizations() const { return relinearizations_; }
  /// Solves in which the heading prior chose a rival over the best fit by cost (all calls).
  int headingDecisions() const { return heading_decisions_; }
  /// Poses whose heading contradicted the prior (beyond `ambiguity_chi2`, 1 dof): kept without it.
  int headingPriorRejections() const { return heading_prior_rejections_; }
  /// Why the last `solve` refused.
  const std::string& reason() const { return reason_; }
  /// Data span currently held [s].
  double spanSeconds() const;
  /// Start of the window the next `solve` fits: `window_s` back from the newest IMU sample, or
  /// further (at most `max_window_s`) until it holds `min_ranges` ranges.
  Timestamp windowStart() const;
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
    double bh = 0.0;                                ///< rangefinder bias b_H [m]
    /// x ⊞ δ with δ = [δp₀, δv₀, δθ, δb_a, δb_ω, δb_H].
    Unknowns plus(const Eigen::Matrix<double, 16, 1>& d) const;
  };

 private:
  struct Obs {
    AlignRange r;
    Increments inc;
    bool use = true;
  };
  struct HeightObs {
    AlignHeight h;
    Increments inc;
    bool use = true;
  };
  using Info = Eigen::Matrix<double, 16, 16>;
  /// A start of the multi-start after its fit.
  struct Candidate {
    Unknowns x;
    double cost;
    ImuState end;
  };
  /// The window's observations, integrated at the gyro bias `b_lin`, and the fitted starts (best first).
  struct Window {
    std::vector<Obs> obs;
    std::vector<HeightObs> heights;
    Increments end;
    Eigen::Vector3d b_lin = Eigen::Vector3d::Zero();
    Eigen::Vector3d dbg_prior_mean = Eigen::Vector3d::Zero();  ///< the caller's bias − b_lin [rad/s]
    std::vector<Candidate> cands;
  };
  /// Builds the observations and fits every start, integrating again at the best fit's gyro bias
  /// while its correction turns the attitude by more than `relinearize_rad`; false (see `reason_`)
  /// with too few ranges or no converged fit.
  bool fitStarts(const Eigen::Vector3d& bias_gyro_rad_s, Window* w);
  std::vector<Obs> buildObservations(const Eigen::Vector3d& bias_gyro, Increments* end,
                                     std::vector<HeightObs>* heights) const;
  /// Levenberg–Marquardt with Huber weights; returns the cost (Huber terms and bias priors).
  /// `dbg_prior_mean`: the prior mean of δb_ω, the caller's gyro bias minus the one the increments
  /// were integrated with (nonzero after a re-integration) [rad/s].
  double fit(const std::vector<Obs>& obs, const std::vector<HeightObs>& heights, const Eigen::Vector3d& dbg_prior_mean,
             Unknowns& x, Info* info) const;
  /// huber::varianceFactor of the inlier ranges: how much noisier than their σ they fit.
  double robustVarianceFactor(const std::vector<Obs>& obs, const Unknowns& x) const;
  /// Range residual d − ‖p_A − p_T‖ and, when `J` is given, its Jacobian ∂r/∂[δp₀, δv₀, δθ, δb_a, δb_ω,
  /// δb_H] (analytic; the noise-free unit test converges with it), from one evaluation of the model:
  /// the Levenberg–Marquardt loop needs both at every observation, and the attitude C(τ) Exp(J_C δb_ω)
  /// (an SO(3) exponential per observation) is the fit's largest cost.
  double residual(const Obs& o, const Unknowns& x, Eigen::Matrix<double, 1, 16>* J = nullptr) const;
  /// Height residual h − ĥ and, when `J` is given, its Jacobian (same unknowns).
  double residual(const HeightObs& o, const Unknowns& x, Eigen::Matrix<double, 1, 16>* J = nullptr) const;
  /// C(τ) Exp(J_C δb_ω): the body attitude at τ relative to R₀, corrected to first order in δb_ω.
  static Eigen::Matrix3d attitude(const Increments& inc, const Unknowns& x);
  /// The body-frame vector w = S − M b_a + C p_TinI (δb_ω-corrected) with which the point p_TinI
  /// of the body (τ of `inc`) is R₀ w away from the gravity/velocity terms; `C` = attitude(inc, x).
  static Eigen::Vector3d bodyTerm(const Increments& inc, const Unknowns& x, const Eigen::Vector3d& p_TinI,
                                  const Eigen::Matrix3d& C);
  ImuState endState(const Unknowns& x, const Increments& end, const Eigen::Vector3d& bias_gyro) const;
  /// The multi-start: positions (and their mirror across nearly coplanar anchors) × a yaw grid ×
  /// the roll and pitch levelled from the mean specific force and, when it differs by more than
  /// kLevelBasin_rad, from the window's integrated specific force `end.V` (motion_aligner_fit.cpp).
  std::vector<Unknowns> starts(const std::vector<Obs>& obs, const Increments& end) const;
  /// Two levellings of the starts closer than this fall in one basin of the fit: one set of
  /// starts is enough [rad] (2°).
  static constexpr double kLevelBasin_rad = 2.0 * M_PI / 180.0;
  /// Covariance, end state and the acceptance checks of the best fit. With `heading`, the end
  /// state is first combined with the prior heading (a Kalman update of the yaw, H = [0 0 nᵀ 0 0],
  /// n = R_ItoGᵀ e_z, so that the fit's heading and the prior's weigh by their variances) unless
  /// its innovation r²/s exceeds `ambiguity_chi2`; the checks then judge the pose.
  std::optional<AlignmentResult> finish(const std::vector<Obs>& obs, const std::vector<HeightObs>& heights,
                                        const Unknowns& x, const Info& info, const Increments& end,
                                        const Eigen::Vector3d& bias_gyro,
                                        const std::optional<HeadingPrior>& heading = std::nullopt);

  /// g = (0, 0, sign·|g|) in G: the assumed sign everywhere but inside `checkGravityDirection`.
  Eigen::Vector3d gravityG() const { return {0.0, 0.0, gravity_z_sign_ * options_.gravity_m_s2}; }

  MotionAlignerOptions options_;
  double gravity_z_sign_ = -1.0, assumed_gravity_z_sign_ = -1.0;
  int relinearizations_ = 0;  ///< re-integrations over this aligner's life
  int heading_decisions_ = 0;  ///< solves whose heading prior chose a rival (headingDecisions)
  int heading_prior_rejections_ = 0;  ///< priors the pose contradicted (headingPriorRejections)
  /// The caller's gyro bias (the prior's centre) and the bias the best fit of the last solve found
  /// about it; the next solve with the same prior integrates at the latter [rad/s]
  std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> last_fit_;
  std::map<SensorId, Eigen::Vector3d> tags_p_TinI_;
  std::deque<ImuSample> imu_;
  std::deque<AlignRange> ranges_;
  std::deque<AlignHeight> heights_;
  std::string reason_ = "no data";
};

}  // namespace meshnav::estimator
