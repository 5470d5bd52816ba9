#include "calibrator/range_model.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

namespace meshnav::calib {

namespace {
constexpr double kMinDistance = 1e-6;  // [m] guard of the unit vector

/// Inverse of a symmetric positive-definite matrix, or an empty matrix when it is not.
Eigen::MatrixXd spdInverse(const Eigen::MatrixXd& H) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(H);
  if (es.info() != Eigen::Success) return {};
  const auto& ev = es.eigenvalues();
  if (ev.minCoeff() <= ev.maxCoeff() * 1e-14 || ev.minCoeff() <= 0.0) return {};
  return es.eigenvectors() * ev.cwiseInverse().asDiagonal() * es.eigenvectors().transpose();
}
}  // namespace

double predictRange(const CalibrationProblem& pb, const AnchorParams& x, int i) {
  const auto& o = pb.observations()[static_cast<size_t>(i)];
  const int s = pb.slotOf(i);
  const double d = (x.p_AinG - o.p_RinG).norm();
  return x.beta[static_cast<size_t>(s)] * d + x.gamma_m[static_cast<size_t>(s)];
}

double effectiveSigma(const CalibrationProblem& pb, const AnchorParams& x, int i) {
  const auto& o = pb.observations()[static_cast<size_t>(i)];
  const int s = pb.slotOf(i);
  const Eigen::Vector3d diff = x.p_AinG - o.p_RinG;
  const double d = std::max(diff.norm(), kMinDistance);
  const Eigen::Vector3d u = diff / d;
  const double b = x.beta[static_cast<size_t>(s)];
  return std::sqrt(o.sigma_d_m * o.sigma_d_m + b * b * u.dot(o.cov_p_RinG_m2 * u));
}

Eigen::VectorXd stack(const CalibrationProblem& pb, const AnchorParams& x) {
  Eigen::VectorXd v = Eigen::VectorXd::Zero(pb.dim());
  v.segment<3>(CalibrationProblem::kPositionIndex) = x.p_AinG;
  for (int s = 0; s < static_cast<int>(pb.slots().size()); ++s) {
    v(pb.gammaIndex(s)) = x.gamma_m[static_cast<size_t>(s)];
    if (pb.betaIndex(s) >= 0) v(pb.betaIndex(s)) = x.beta[static_cast<size_t>(s)];
  }
  return v;
}

AnchorParams unstack(const CalibrationProblem& pb, const Eigen::VectorXd& v) {
  AnchorParams x = pb.priorParams(v.segment<3>(CalibrationProblem::kPositionIndex));
  for (int s = 0; s < static_cast<int>(pb.slots().size()); ++s) {
    x.gamma_m[static_cast<size_t>(s)] = v(pb.gammaIndex(s));
    if (pb.betaIndex(s) >= 0) x.beta[static_cast<size_t>(s)] = v(pb.betaIndex(s));
  }
  return x;
}

Eigen::MatrixXd informationMatrix(const CalibrationProblem& pb, const AnchorParams& x, const std::vector<bool>& use,
                                  bool with_priors) {
  const int n = pb.dim();
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
  const auto& obs = pb.observations();
  // Accumulate per slot in a small dense block [p(3), γ, β] and scatter once.
  for (int s = 0; s < static_cast<int>(pb.slots().size()); ++s) {
    Eigen::Matrix<double, 5, 5> B = Eigen::Matrix<double, 5, 5>::Zero();
    const double beta = x.beta[static_cast<size_t>(s)];
    for (int i : pb.slots()[static_cast<size_t>(s)].obs) {
      if (!use.empty() && !use[static_cast<size_t>(i)]) continue;
      const auto& o = obs[static_cast<size_t>(i)];
      const Eigen::Vector3d diff = x.p_AinG - o.p_RinG;
      const double d = std::max(diff.norm(), kMinDistance);
      const Eigen::Vector3d u = diff / d;
      const double var = o.sigma_d_m * o.sigma_d_m + beta * beta * u.dot(o.cov_p_RinG_m2 * u);
      Eigen::Matrix<double, 5, 1> j;
      j << beta * u, 1.0, d;
      B.noalias() += j * j.transpose() / var;
    }
    const int ig = pb.gammaIndex(s), ib = pb.betaIndex(s);
    H.block<3, 3>(0, 0) += B.block<3, 3>(0, 0);
    H.block<3, 1>(0, ig) += B.block<3, 1>(0, 3);
    H.block<1, 3>(ig, 0) += B.block<1, 3>(3, 0);
    H(ig, ig) += B(3, 3);
    if (ib >= 0) {
      H.block<3, 1>(0, ib) += B.block<3, 1>(0, 4);
      H.block<1, 3>(ib, 0) += B.block<1, 3>(4, 0);
      H(ig, ib) += B(3, 4);
      H(ib, ig) += B(4, 3);
      H(ib, ib) += B(4, 4);
    }
    if (with_priors) {
      const auto& pr = pb.slots()[static_cast<size_t>(s)].prior;
      if (pr.sigma_gamma_m > 0) H(ig, ig) += 1.0 / (pr.sigma_gamma_m * pr.sigma_gamma_m);
      if (ib >= 0 && pr.sigma_beta > 0) H(ib, ib) += 1.0 / (pr.sigma_beta * pr.sigma_beta);
    }
  }
  return H;
}

CovarianceEstimate estimateCovariance(const CalibrationProblem& pb, const AnchorParams& x,
                                      const std::vector<bool>& use, bool scale_by_residuals,
                                      double correlated_reference_fraction) {
  CovarianceEstimate c;
  const Eigen::MatrixXd H = informationMatrix(pb, x, use, /*with_priors=*/true);
  c.P = spdInverse(H);
  if (c.P.size() == 0) return c;
  double chi2 = 0.0;
  for (int i = 0; i < static_cast<int>(pb.observations().size()); ++i) {
    if (pb.slotOf(i) < 0 || (!use.empty() && !use[static_cast<size_t>(i)])) continue;
    const double r = (pb.observations()[static_cast<size_t>(i)].z_m - predictRange(pb, x, i)) / effectiveSigma(pb, x, i);
    chi2 += r * r;
    ++c.n;
  }
  const int dof = c.n - pb.dim();
  c.s2 = dof > 0 ? chi2 / dof : 1.0;
  if (scale_by_residuals && c.s2 > 1.0) c.P *= c.s2;
  if (correlated_reference_fraction > 0.0) {
    // Sensitivity of the estimate to a shift δ common to every moving reference.
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(pb.dim(), 3);
    Eigen::Matrix3d cov_sum = Eigen::Matrix3d::Zero();
    int n_moving = 0;
    for (int s = 0; s < static_cast<int>(pb.slots().size()); ++s) {
      const auto& slot = pb.slots()[static_cast<size_t>(s)];
      if (!slot.moving) continue;
      const double beta = x.beta[static_cast<size_t>(s)];
      const int ig = pb.gammaIndex(s), ib = pb.betaIndex(s);
      for (int i : slot.obs) {
        if (!use.empty() && !use[static_cast<size_t>(i)]) continue;
        const auto& o = pb.observations()[static_cast<size_t>(i)];
        const Eigen::Vector3d diff = x.p_AinG - o.p_RinG;
        const double d = std::max(diff.norm(), kMinDistance);
        const Eigen::Vector3d u = diff / d;
        const double var = o.sigma_d_m * o.sigma_d_m + beta * beta * u.dot(o.cov_p_RinG_m2 * u);
        const Eigen::RowVector3d dr = beta * u.transpose() / var;  // ∂r/∂δ, whitened once
        G.topRows<3>() += beta * u * dr;
        G.row(ig) += dr;
        if (ib >= 0) G.row(ib) += d * dr;
        cov_sum += o.cov_p_RinG_m2;
        ++n_moving;
      }
    }
    if (n_moving > 0) {
      const Eigen::MatrixXd S = spdInverse(H) * G;
      const Eigen::Matrix3d cov_mean = cov_sum / n_moving;
      c.P += correlated_reference_fraction * S * cov_mean * S.transpose();
    }
  }
  c.ok = c.P.allFinite();
  return c;
}

Eigen::MatrixXd cramerRaoBound(const CalibrationProblem& pb, const AnchorParams& truth) {
  return spdInverse(informationMatrix(pb, truth, {}, /*with_priors=*/true));
}

double crbPositionRmse(const CalibrationProblem& pb, const AnchorParams& truth) {
  const Eigen::MatrixXd P = cramerRaoBound(pb, truth);
  if (P.size() == 0) return std::numeric_limits<double>::quiet_NaN();
  return std::sqrt(P.block<3, 3>(0, 0).trace());
}

}  // namespace meshnav::calib
