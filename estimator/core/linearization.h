#pragma once
/// @file linearization.h
/// @brief A linearized measurement with Jacobians named per instance (MaRS style):
/// r = z − h(x̂) ≈ Σ_i H_i δx_i + ν, ν ~ N(0, R). A strategy stacks the blocks it holds.

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

#include "common/types.h"
#include "estimator/core/huber.h"
#include "estimator/core/nlos_mixture.h"

namespace meshnav::estimator {

/// ∂r/∂δx_i of one instance i (rows = measurement dimension, cols = instance error dimension).
struct JacobianBlock {
  SensorId id = 0;
  Eigen::MatrixXd H;
};

struct Linearization {
  Eigen::VectorXd residual;        ///< r = z − h(x̂)
  Eigen::MatrixXd R;               ///< measurement noise covariance
  std::vector<JacobianBlock> blocks;
  /// > 0: Huber-weighted update of a scalar measurement (docs/robustness.md, "Ranges that pass the
  /// gate"; ignored for m > 1): with e = √NIS beyond k, the innovation covariance S is taken as
  /// S·e/k (R grows by S·(e/k − 1)), so the step is k/e of the plain one (the innovation clipped
  /// to k√S) and P shrinks less. The reported NIS and the gate stay those of the stated R.
  /// 0: the plain update.
  double huber_k = 0.0;
  /// The weighting only while the state's share of S is small, H P Hᵀ ≤ this · R: then a large
  /// innovation is the measurement's; beyond, it is more likely the state's own error, which the
  /// update must correct in full (a filter that has drifted would otherwise never catch up).
  double huber_max_prior_ratio = 1.0;
  /// > 0: a scalar range whose error is a line-of-sight / NLOS mixture (nlos_mixture.h) with this
  /// prior NLOS probability ε and excess nlos_min_m + Exp(nlos_mean_m): its step is the mixture's
  /// posterior collapsed to one Gaussian (scalarStep), its gate Gaussian (passesGate); 0: Gaussian only.
  double nlos_fraction = 0.0;
  double nlos_min_m = 0.2;
  double nlos_mean_m = 0.3;
  /// ≥ 1: the step weights the measurement as if its noise were R·this (an error correlated with
  /// the previous one of its pair brings less new information: (1+ρ)/(1−ρ),
  /// estimator/uwb/range_error_correlation.h). The gate, the NIS and every statistic built on it
  /// judge the measurement by R, the marginal distribution of its own error (docs/uwb_bias_model.md,
  /// "Correlated errors"); 1: white errors.
  double step_noise_factor = 1.0;
  int dim() const { return static_cast<int>(residual.size()); }
  /// The innovation covariance of the step for s = H P Hᵀ + R that passed the gate:
  /// (s + (step_noise_factor − 1) R) · `robust`, the Huber weight huberInflation(nis, s) judged
  /// on the stated s (the dense and the DAH update both take it from here).
  template <class Mat>
  Mat stepCovariance(const Mat& s, double robust) const {
    Mat out = s;
    if (step_noise_factor > 1.0) out += (step_noise_factor - 1.0) * R;
    return out * robust;
  }
  /// Whether the NLOS mixture is this measurement's error model at innovation covariance s: a
  /// scalar with ε > 0 while the measurement dominates s (H P Hᵀ ≤ huber_max_prior_ratio · R;
  /// beyond, a long range is more likely the state's own error).
  bool nlosApplies(double s) const {
    return dim() == 1 && nlos_fraction > 0.0 && (s - R(0, 0)) / R(0, 0) <= huber_max_prior_ratio;
  }
  /// The gate at `nis` = rᵀ S⁻¹ r against `nis_gate` (χ²(m) quantile of the gate probability; 0 = off),
  /// Gaussian also under the NLOS mixture: the health monitor, the process-noise adapter and the
  /// reentry check judge the NIS of what passed as χ². (The mixture's own tail as the gate, with
  /// the normal score of r as the NIS, passed 0.5–1.3 m outliers of the paper's model as NLOS and
  /// lost a one-tag lawnmower; docs/uwb_bias_model.md, "NLOS excess".)
  bool passesGate(double nis, double nis_gate) const {
    return std::isfinite(nis) && !(nis_gate > 0.0 && nis > nis_gate);
  }
  /// The step of a scalar measurement that passed the gate at stated s = H P Hᵀ + R: with u = P Hᵀ,
  ///     δx = u · residual / s_step,   P ← P − u uᵀ (s_step − spread) / s_step²,
  /// s_step = stepCovariance(s, Huber weight) and, under the NLOS mixture, the innovation and the
  /// spread of the mixture's collapse (nlos::collapse, judged on s); without it the plain step
  /// (residual r, spread 0). The dense and the DAH update both take it from here.
  struct ScalarStep {
    double s_step = 0.0;     ///< innovation covariance of the gain [m²]
    double residual = 0.0;   ///< innovation used [m]
    double spread_m2 = 0.0;  ///< what the covariance reduction gives back [m²]
  };
  ScalarStep scalarStep(double s, double nis) const {
    ScalarStep out;
    Eigen::Matrix<double, 1, 1> S;
    S(0, 0) = s;
    out.s_step = stepCovariance(S, huberInflation(nis, s))(0, 0);
    out.residual = residual(0);
    if (nlosApplies(s)) {
      const nlos::MixtureStep mix = nlos::collapse(residual(0), s, nlos_fraction, nlos_min_m, nlos_mean_m);
      out.residual = mix.residual;
      out.spread_m2 = mix.spread_m2;
    }
    return out;
  }
  /// The factor on the innovation covariance s = H P Hᵀ + R of this (scalar) measurement after
  /// the gate passed it at `nis` (huber::innovationInflation); 1 when off or not scalar.
  double huberInflation(double nis, double s) const {
    if (!(huber_k > 0.0) || dim() != 1) return 1.0;
    return huber::innovationInflation(nis, huber_k, (s - R(0, 0)) / R(0, 0), huber_max_prior_ratio);
  }
  /// The block of instance `id`, or nullptr.
  const JacobianBlock* find(SensorId id) const {
    for (const auto& b : blocks)
      if (b.id == id) return &b;
    return nullptr;
  }
};

}  // namespace meshnav::estimator
