#include "estimator/filter/dense_ekf_update.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <stdexcept>
#include <string>

namespace meshnav::estimator {

DenseUpdateOutput denseEkfUpdate(Eigen::MatrixXd& P, const StateLayout& layout, const Linearization& lin,
                                 double nis_gate, bool joseph_form) {
  const int n = layout.dim(), m = lin.dim();
  // U = P Hᵀ and S = H P Hᵀ + R from the named blocks (H is zero elsewhere).
  Eigen::MatrixXd U = Eigen::MatrixXd::Zero(n, m);
  for (const JacobianBlock& jb : lin.blocks) {
    const StateBlock& b = layout.at(jb.id);
    if (jb.H.rows() != m || jb.H.cols() != b.dim)
      throw std::logic_error("EKF update: Jacobian block of " + std::to_string(jb.id) + " has wrong size");
    U.noalias() += P.middleCols(b.offset, b.dim) * jb.H.transpose();
  }
  Eigen::MatrixXd S = lin.R;
  for (const JacobianBlock& jb : lin.blocks) {
    const StateBlock& b = layout.at(jb.id);
    S.noalias() += jb.H * U.middleRows(b.offset, b.dim);
  }
  S = 0.5 * (S + S.transpose()).eval();
  Eigen::LDLT<Eigen::MatrixXd> ldlt(S);
  DenseUpdateOutput out;
  out.nis = lin.residual.dot(ldlt.solve(lin.residual));
  if (!std::isfinite(out.nis) || (nis_gate > 0.0 && out.nis > nis_gate)) return out;
  // Correlated errors and robust weights, after the gate: R_eff = R·f + S'(inflate − 1); the Joseph
  // form below uses S = H P Hᵀ + R_eff.
  if (const double robust = lin.robustInflation(out.nis, S(0, 0)); lin.step_noise_factor > 1.0 || robust > 1.0) {
    S = lin.stepCovariance(S, robust);
    ldlt.compute(S);
  }
  out.K = ldlt.solve(U.transpose()).transpose();  // n × m
  out.dx = out.K * lin.residual;
  if (m == 1) {
    // One row of H (a range, the baro): K Uᵀ and K S Kᵀ are outer products. The form and the
    // symmetrization below in one pass over the pairs (i ≥ j), in place, with the arithmetic of the
    // matrix expressions per coefficient (the same values, without their three n × n temporaries).
    const double s = S(0, 0);
    const double* k = out.K.data();
    const double* u = U.data();
    for (Eigen::Index j = 0; j < n; ++j)
      for (Eigen::Index i = j; i < n; ++i) {
        double a, b;  // the new P(i, j) and P(j, i) before the symmetrization
        if (joseph_form) {
          a = P(i, j) + ((-(k[i] * u[j]) - k[j] * u[i]) + (k[i] * s) * k[j]);
          b = P(j, i) + ((-(k[j] * u[i]) - k[i] * u[j]) + (k[j] * s) * k[i]);
        } else {
          a = P(i, j) - k[i] * u[j];
          b = P(j, i) - k[j] * u[i];
        }
        P(i, j) = P(j, i) = 0.5 * (a + b);
      }
    out.S = std::move(S);
    out.accepted = true;
    return out;
  }
  if (joseph_form) {
    const Eigen::MatrixXd KU = out.K * U.transpose();
    P += -KU - KU.transpose() + out.K * S * out.K.transpose();
  } else {
    P.noalias() -= out.K * U.transpose();
  }
  P = 0.5 * (P + P.transpose()).eval();
  out.S = std::move(S);
  out.accepted = true;
  return out;
}

}  // namespace meshnav::estimator
