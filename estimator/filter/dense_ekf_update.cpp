#include "estimator/filter/dense_ekf_update.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>
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
  if (!lin.passesGate(out.nis, nis_gate)) return out;
  if (m == 1) {
    // One row of H (a range, the baro): the step of Linearization::scalarStep, K = u / s_step,
    // δx = K r', P ← P − K uᵀ − u Kᵀ + K (s_step + c) Kᵀ (Joseph) or P − K uᵀ + K c Kᵀ: both
    // P − u uᵀ (s_step − c)/s_step². Outer products, with the symmetrization in one pass over the
    // pairs (i ≥ j), in place (without the matrix expressions' three n × n temporaries).
    const Linearization::ScalarStep st = lin.scalarStep(S(0, 0), out.nis);
    const double s = st.s_step, c = st.spread_m2;
    // s = 0 (an exact measurement of an exact state): K = 0, as LDLT's pseudo-inverse gave.
    out.K = std::abs(s) > std::numeric_limits<double>::min() ? Eigen::MatrixXd(U / s) : Eigen::MatrixXd::Zero(n, 1);
    out.dx = out.K * st.residual;
    const double* k = out.K.data();
    const double* u = U.data();
    for (Eigen::Index j = 0; j < n; ++j)
      for (Eigen::Index i = j; i < n; ++i) {
        double a, b;  // the new P(i, j) and P(j, i) before the symmetrization
        if (joseph_form) {
          a = P(i, j) + ((-(k[i] * u[j]) - k[j] * u[i]) + (k[i] * (s + c)) * k[j]);
          b = P(j, i) + ((-(k[j] * u[i]) - k[i] * u[j]) + (k[j] * (s + c)) * k[i]);
        } else {
          a = P(i, j) - k[i] * u[j] + (k[i] * c) * k[j];
          b = P(j, i) - k[j] * u[i] + (k[j] * c) * k[i];
        }
        P(i, j) = P(j, i) = 0.5 * (a + b);
      }
    out.S = Eigen::MatrixXd::Constant(1, 1, s);
    out.accepted = true;
    return out;
  }
  // Correlated errors (step_noise_factor), after the gate: R_eff = R·f; the Joseph form below uses
  // S = H P Hᵀ + R_eff. No robust weight for m > 1.
  if (lin.step_noise_factor > 1.0) {
    S = lin.stepCovariance(S, 1.0);
    ldlt.compute(S);
  }
  out.K = ldlt.solve(U.transpose()).transpose();  // n × m
  out.dx = out.K * lin.residual;
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
