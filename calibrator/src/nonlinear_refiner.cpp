#include "calibrator/nonlinear_refiner.h"

#include <ceres/ceres.h>

#include <cmath>
#include <memory>
#include <vector>

#include "calibrator/range_model.h"

namespace meshnav::calib {

namespace {

/// All ranges of one reference in one residual block (few blocks → little solver overhead).
/// Whitened residuals r_i = (z_i − β‖p − p_R,i‖ − γ)/σ_i; with a robust loss ρ each is replaced by
/// r̃_i = sign(r_i)·√ρ(r_i²), so that Σ r̃_i² = Σ ρ(r_i²) is exactly the robust cost, with Jacobian
/// ∂r̃_i = ρ'(r_i²)·r_i/√ρ(r_i²)·∂r_i (→ ∂r_i as r_i → 0).
class ReferenceRanges final : public ceres::CostFunction {
 public:
  struct Item {
    Eigen::Vector3d p_RinG;
    double z_m;
    double inv_sigma;
  };
  ReferenceRanges(std::vector<Item> items, RobustLoss loss, double scale)
      : items_(std::move(items)), loss_(loss), c2_(scale * scale), c_(scale) {
    set_num_residuals(static_cast<int>(items_.size()));
    mutable_parameter_block_sizes()->assign({3, 1, 1});
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const Eigen::Map<const Eigen::Vector3d> p(parameters[0]);
    const double gamma = parameters[1][0];
    const double beta = parameters[2][0];
    for (size_t i = 0; i < items_.size(); ++i) {
      const auto& it = items_[i];
      const Eigen::Vector3d diff = p - it.p_RinG;
      const double d = std::max(diff.norm(), 1e-9);
      const double r = (it.z_m - beta * d - gamma) * it.inv_sigma;
      double scale = 1.0;  // ∂r̃/∂r
      double rr = r;
      robustify(r, rr, scale);
      residuals[i] = rr;
      if (!jacobians) continue;
      const double f = -scale * it.inv_sigma;
      if (jacobians[0]) {
        const Eigen::Vector3d g = f * beta * diff / d;
        jacobians[0][3 * i + 0] = g.x();
        jacobians[0][3 * i + 1] = g.y();
        jacobians[0][3 * i + 2] = g.z();
      }
      if (jacobians[1]) jacobians[1][i] = f;
      if (jacobians[2]) jacobians[2][i] = f * d;
    }
    return true;
  }

 private:
  void robustify(double r, double& rr, double& scale) const {
    const double s = r * r;
    double rho = s, drho = 1.0;
    switch (loss_) {
      case RobustLoss::None: return;
      case RobustLoss::Huber:
        if (s > c2_) {
          const double a = std::sqrt(s);
          rho = 2.0 * c_ * a - c2_;
          drho = c_ / a;
        }
        break;
      case RobustLoss::Cauchy:
        rho = c2_ * std::log1p(s / c2_);
        drho = 1.0 / (1.0 + s / c2_);
        break;
    }
    if (s < 1e-24) return;  // ρ(s) ≈ s: r̃ = r, ∂r̃/∂r = 1
    const double sq = std::sqrt(rho);
    rr = r < 0 ? -sq : sq;
    scale = drho * std::abs(r) / sq;
  }

  std::vector<Item> items_;
  RobustLoss loss_;
  double c2_, c_;
};

/// Scalar Gaussian prior (x − mean)/σ.
class ScalarPrior final : public ceres::SizedCostFunction<1, 1> {
 public:
  ScalarPrior(double mean, double sigma) : mean_(mean), inv_sigma_(1.0 / sigma) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    residuals[0] = (parameters[0][0] - mean_) * inv_sigma_;
    if (jacobians && jacobians[0]) jacobians[0][0] = inv_sigma_;
    return true;
  }

 private:
  double mean_, inv_sigma_;
};

}  // namespace

RefineResult NonlinearRefiner::refine(const CalibrationProblem& pb, const AnchorParams& init,
                                      const std::vector<bool>& use) const {
  RefineResult out;
  out.params = init;
  AnchorParams& x = out.params;
  const size_t n_slots = pb.slots().size();

  ceres::Problem problem;
  std::vector<bool> slot_used(n_slots, false);
  const auto& obs = pb.observations();
  for (size_t s = 0; s < n_slots; ++s) {
    std::vector<ReferenceRanges::Item> items;
    for (int i : pb.slots()[s].obs) {
      if (!use.empty() && !use[static_cast<size_t>(i)]) continue;
      const auto& o = obs[static_cast<size_t>(i)];
      items.push_back({o.p_RinG, o.z_m, 1.0 / effectiveSigma(pb, init, i)});
    }
    if (items.empty()) continue;
    problem.AddResidualBlock(new ReferenceRanges(std::move(items), options_.robust_loss, options_.robust_loss_scale),
                             nullptr, x.p_AinG.data(), &x.gamma_m[s], &x.beta[s]);
    slot_used[s] = true;
  }
  for (size_t s = 0; s < n_slots; ++s) {
    const auto& slot = pb.slots()[s];
    if (slot.prior.sigma_gamma_m > 0 && slot_used[s])
      problem.AddResidualBlock(new ScalarPrior(slot.prior.gamma_m, slot.prior.sigma_gamma_m), nullptr, &x.gamma_m[s]);
    if (!slot_used[s]) continue;
    if (slot.estimate_beta) {
      if (slot.prior.sigma_beta > 0)
        problem.AddResidualBlock(new ScalarPrior(slot.prior.beta, slot.prior.sigma_beta), nullptr, &x.beta[s]);
    } else {
      x.beta[s] = slot.prior.beta;
      problem.SetParameterBlockConstant(&x.beta[s]);
    }
  }
  if (problem.NumResidualBlocks() == 0) {
    out.message = "no observations";
    return out;
  }

  ceres::Solver::Options sopts;
  sopts.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  sopts.minimizer_type = ceres::TRUST_REGION;
  sopts.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  sopts.max_num_iterations = options_.lm_max_iterations;
  sopts.function_tolerance = 1e-10;
  sopts.gradient_tolerance = 1e-12;
  sopts.parameter_tolerance = 1e-10;
  sopts.num_threads = 1;
  sopts.logging_type = ceres::SILENT;
  sopts.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(sopts, &problem, &summary);
  out.converged = summary.IsSolutionUsable() && x.p_AinG.allFinite();
  out.iterations = static_cast<int>(summary.iterations.size());
  out.final_cost = summary.final_cost;
  out.message = summary.BriefReport();
  return out;
}

}  // namespace meshnav::calib
