#pragma once
/// @file batch_smoother.h
/// @brief Least-squares smoother of a SmoothingProblem (Ceres): every knot's state given all the
/// data on both sides of it, relinearized, with a robust loss on the ranges.
///
/// Unknowns: per knot k the pose (p_k, R_k), velocity v_k and biases b_ω,k, b_a,k; the range
/// biases of the problem. Costs (each whitened by its covariance; derivation in docs/smoother.md):
///  * IMU between knots i, j (ImuIncrement, biases corrected to first order):
///      r_φ = Log((ΔR Exp(J_R^ω δb_ω))ᵀ R_iᵀ R_j),
///      r_v = R_iᵀ (v_j − v_i − g Δt) − (Δv + J_v^ω δb_ω + J_v^a δb_a),
///      r_p = R_iᵀ (p_j − p_i − v_i Δt − ½ g Δt²) − (Δp + J_p^ω δb_ω + J_p^a δb_a),
///    weighted by Σ⁻¹ (the IMU noise figures of the setup or the estimator's defaults);
///  * bias random walk: b_j − b_i ~ N(0, σ_rw² Δt I); first knot's biases ~ N(0, σ_b² I);
///  * a range at t between knots k and k+1, from knot k and the increment over [t_k, t]:
///      p_T = p_k + v_k τ + ½ g τ² + R_k (Δp + …) + R_k ΔR Exp(J_R^ω δb_ω) p_TinI,
///      r = (z − γ − β ‖p_A − p_T‖) / σ under a robust loss ρ (Huber or Cauchy, scale k σ):
///    the heavy tail of UWB errors (NLOS excess) gets a bounded (Huber) or vanishing (Cauchy)
///    influence instead of a gate; with `nlos_fraction` ε > 0 each range's error is also the
///    estimator's line-of-sight / NLOS mixture (estimator/core/nlos_mixture.h), fitted by EM over
///    the passes: after a pass, at its solution, the range's posterior probability of line of sight
///    w = (1 − ε) N(r; 0, s) / ((1 − ε) N(r; 0, s) + ε p_N(r)) from its residual r (measured minus
///    predicted) and s = its own σ² (the correlation's inflation left out, as the filter judges a
///    range by its own R); the next pass takes the range with σ²/w (w ≥ 0.01), the loss's scale
///    still k own σ, so that its cost is w ρ(r²/σ²): the loss on top of the weight;
///  * a downward rangefinder's reading (SmootherHeight) like a range, under the same loss, with one
///    bias b_H ~ N(0, σ_bH²) per problem;
///  * landed knots: v = 0, and no turn between two of them (the ZUPT model);
///  * range biases: N(prior mean, prior σ²); the first knot's pose: the optional prior;
///  * anchors the problem lists as unknowns: their positions, without a prior (bundle adjustment).
/// The increments are integrated again at the solved biases between passes.

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "smoother/smoothing_problem.h"

namespace meshnav::smoother {

struct BatchSmootherOptions {
  enum class Loss { Huber, Cauchy };
  Loss range_loss = Loss::Cauchy;  ///< robust loss of the ranges
  double loss_scale_sigmas = 2.0;  ///< the loss's scale in range σ [-]
  int passes = 3;                  ///< solves, each after re-integrating at the solved biases [-]
  /// Prior probability ε that a range carries an NLOS excess b₀ + Exp(μ) (the mixture of the file
  /// comment, one E step per pass after the first); 0: off. smoothRun sets these three from the
  /// estimator's uwb.nlos_fraction, uwb.nlos_min_excess_m and uwb.nlos_mean_excess_m [-]
  double nlos_fraction = 0.0;
  double nlos_offset_m = 0.2;      ///< b₀, the smallest NLOS excess [m]
  double nlos_scale_m = 0.3;       ///< μ, the mean NLOS excess beyond b₀ [m]
  int max_iterations = 50;         ///< Levenberg–Marquardt iterations per solve [-]
  bool covariance = true;          ///< compute each knot's marginal covariance of p and θ
  int threads = 1;
};

/// One knot's smoothed state and marginal covariance.
struct SmoothedKnot {
  NavState x;
  Eigen::Matrix3d cov_p_m2 = Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Matrix3d cov_theta_rad2 = Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN());
};

/// An estimated anchor's position and its marginal covariance.
struct SmoothedAnchor {
  SensorId id = 0;
  Eigen::Vector3d p_AinG = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov_p_m2 = Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN());
};

struct SmootherResult {
  std::vector<SmoothedKnot> knots;
  std::vector<SmoothedAnchor> anchors;  ///< the problem's anchor unknowns
  std::vector<double> range_biases_m;  ///< solved values of the problem's range biases
  double imu_chi2_per_dof = 0.0;       ///< mean whitened IMU residual² per degree of freedom [-]
  double height_bias_m = 0.0;          ///< b_H of the rangefinder (0 without heights) [m]
  int n_heights = 0;
  int n_ranges = 0;
  int n_range_outliers = 0;            ///< ranges beyond 3 loss scales at the solution
  int n_range_nlos = 0;                ///< ranges the last solve took with LOS weight w < 0.5 (ε > 0)
  double range_rms_inliers_m = 0.0;    ///< RMS of the range residuals within 3 loss scales [m]
  bool converged = false;
  bool covariance_ok = false;
  std::string message;                 ///< the last solve's summary line, or why it failed
};

class BatchSmoother {
 public:
  explicit BatchSmoother(BatchSmootherOptions options) : options_(options) {}
  /// Solves. `progress(pass, passes)` is called after each pass when given.
  SmootherResult solve(const SmoothingProblem& problem,
                       const std::function<void(int, int, const std::string&)>& progress = nullptr) const;
  const BatchSmootherOptions& options() const { return options_; }

 private:
  BatchSmootherOptions options_;
};

/// The state at `t` (between knot k and k+1, or at the last knot) predicted from the knot before it
/// by the IMU increments; the covariance is that knot's.
SmoothedKnot stateAt(const std::vector<SmoothedKnot>& knots, const std::vector<ImuSample>& imu,
                     const Eigen::Vector3d& gravity_G, Timestamp t);

}  // namespace meshnav::smoother
