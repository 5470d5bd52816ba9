#include "calibrator/optimal_double_solver.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "calibrator/range_model.h"

namespace meshnav::calib {

namespace {

constexpr double kMinRange = 0.1;  // [m] floor of ẑ in the row weights

/// Pairs i ↔ i + k inside blocks of 2k over positions [0, n) of a sorted index list.
std::vector<std::pair<int, int>> blockPairs(int n, int k) {
  std::vector<std::pair<int, int>> out;
  for (int b = 0; b + 2 * k <= n; b += 2 * k)
    for (int i = 0; i < k; ++i) out.emplace_back(b + i, b + k + i);
  return out;
}

}  // namespace

std::vector<std::pair<int, int>> OptimalDoubleSolver::selectPairs(const CalibrationProblem& pb,
                                                                  const std::vector<int>& idx,
                                                                  const std::vector<double>& rho,
                                                                  const std::vector<double>& var_half) {
  const int n = static_cast<int>(idx.size());
  std::vector<std::pair<int, int>> best;
  if (n < 2) return best;
  double best_score = std::numeric_limits<double>::infinity();
  std::vector<int> ks;
  for (int k = n / 2; k >= 1; k /= 2) ks.push_back(k);
  const auto& obs = pb.observations();
  for (int k : ks) {
    auto local = blockPairs(n, k);
    // Information of [p, γ] from these rows, γ marginalised.
    Eigen::Matrix4d I = Eigen::Matrix4d::Zero();
    for (auto [a, b] : local) {
      Eigen::Vector4d row;
      row.head<3>() = 2.0 * (obs[static_cast<size_t>(idx[static_cast<size_t>(a)])].p_RinG -
                             obs[static_cast<size_t>(idx[static_cast<size_t>(b)])].p_RinG);
      row(3) = -2.0 * (rho[static_cast<size_t>(a)] - rho[static_cast<size_t>(b)]);
      I.noalias() += row * row.transpose() / (var_half[static_cast<size_t>(a)] + var_half[static_cast<size_t>(b)]);
    }
    Eigen::Matrix3d M = I.topLeftCorner<3, 3>();
    if (I(3, 3) > 0) M -= I.topRightCorner<3, 1>() * I.bottomLeftCorner<1, 3>() / I(3, 3);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(M);
    const double lmin = es.eigenvalues()(0);
    const double score = lmin > 1e-12 * std::max(1.0, es.eigenvalues()(2)) ? es.eigenvalues().cwiseInverse().sum()
                                                                            : std::numeric_limits<double>::infinity();
    if (best.empty() || score < best_score) {
      best_score = score;
      best.clear();
      for (auto [a, b] : local) best.emplace_back(idx[static_cast<size_t>(a)], idx[static_cast<size_t>(b)]);
    }
  }
  return best;
}

LinearSolution OptimalDoubleSolver::solve(const CalibrationProblem& pb, const std::vector<int>& subset) const {
  LinearSolution sol;
  const auto& obs = pb.observations();
  const int n_slots = static_cast<int>(pb.slots().size());

  // Observations per slot (time order = index order, the problem is time-sorted).
  std::vector<std::vector<int>> per_slot(static_cast<size_t>(n_slots));
  if (subset.empty()) {
    for (int s = 0; s < n_slots; ++s) per_slot[static_cast<size_t>(s)] = pb.slots()[static_cast<size_t>(s)].obs;
  } else {
    std::vector<int> sorted = subset;
    std::sort(sorted.begin(), sorted.end());
    for (int i : sorted)
      if (pb.slotOf(i) >= 0) per_slot[static_cast<size_t>(pb.slotOf(i))].push_back(i);
  }

  // Unknown layout of the linear system: [p (3), γ of each moving slot with ≥ 2 ranges].
  std::vector<int> lin_col(static_cast<size_t>(n_slots), -1);
  int u = 3;
  for (int s = 0; s < n_slots; ++s)
    if (pb.slots()[static_cast<size_t>(s)].moving && per_slot[static_cast<size_t>(s)].size() >= 2)
      lin_col[static_cast<size_t>(s)] = u++;
  if (u == 3) {
    sol.reason = "no moving reference with at least 2 ranges";
    return sol;
  }

  auto sigma2 = [&](int i) {
    const auto& o = obs[static_cast<size_t>(i)];
    return o.sigma_d_m * o.sigma_d_m + o.cov_p_RinG_m2.trace() / 3.0;
  };

  // Pass 1 pairing and regressors (ρ = z).
  std::vector<std::vector<std::pair<int, int>>> pairs(static_cast<size_t>(n_slots));
  for (int s = 0; s < n_slots; ++s) {
    if (lin_col[static_cast<size_t>(s)] < 0) continue;
    const auto& idx = per_slot[static_cast<size_t>(s)];
    std::vector<double> rho, var_half;
    for (int i : idx) {
      const double z = std::max(obs[static_cast<size_t>(i)].z_m, kMinRange);
      rho.push_back(obs[static_cast<size_t>(i)].z_m);
      var_half.push_back(4.0 * sigma2(i) * z * z);
    }
    pairs[static_cast<size_t>(s)] = selectPairs(pb, idx, rho, var_half);
  }

  // One weighted LS solve given the regressor ρ_i and the predicted range ẑ_i (for the weights).
  auto solveOnce = [&](const std::vector<double>& rho_all, const std::vector<double>& zhat_all,
                       const std::vector<double>& s2_all, Eigen::VectorXd& x) -> bool {
    Eigen::MatrixXd N = Eigen::MatrixXd::Zero(u, u);
    Eigen::VectorXd r = Eigen::VectorXd::Zero(u);
    int rows = 0;
    for (int s = 0; s < n_slots; ++s) {
      const int col = lin_col[static_cast<size_t>(s)];
      if (col < 0) continue;
      for (auto [i, j] : pairs[static_cast<size_t>(s)]) {
        const auto& o1 = obs[static_cast<size_t>(i)];
        const auto& o2 = obs[static_cast<size_t>(j)];
        Eigen::Vector3d ap = 2.0 * (o1.p_RinG - o2.p_RinG);
        const double ag = -2.0 * (rho_all[static_cast<size_t>(i)] - rho_all[static_cast<size_t>(j)]);
        double b = o1.p_RinG.squaredNorm() - o2.p_RinG.squaredNorm() - (o1.z_m * o1.z_m - o2.z_m * o2.z_m);
        b += o1.sigma_d_m * o1.sigma_d_m - o2.sigma_d_m * o2.sigma_d_m;
        b -= o1.cov_p_RinG_m2.trace() - o2.cov_p_RinG_m2.trace();
        const double z1 = std::max(zhat_all[static_cast<size_t>(i)], kMinRange);
        const double z2 = std::max(zhat_all[static_cast<size_t>(j)], kMinRange);
        const double w = 1.0 / (4.0 * (s2_all[static_cast<size_t>(i)] * z1 * z1 + s2_all[static_cast<size_t>(j)] * z2 * z2));
        N.topLeftCorner<3, 3>().noalias() += w * ap * ap.transpose();
        N.block(0, col, 3, 1) += w * ag * ap;
        N.block(col, 0, 1, 3) += w * ag * ap.transpose();
        N(col, col) += w * ag * ag;
        r.head<3>() += w * b * ap;
        r(col) += w * b * ag;
        ++rows;
      }
    }
    sol.n_rows = rows;
    if (rows < u) return false;
    // Scale-invariant rank test on the normalised normal matrix.
    const Eigen::VectorXd dg = N.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
    const Eigen::MatrixXd Nn = dg.asDiagonal() * N * dg.asDiagonal();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Nn, Eigen::EigenvaluesOnly);
    if (!(es.eigenvalues()(0) > 1e-10 * es.eigenvalues()(u - 1))) return false;
    x = N.ldlt().solve(r);
    return x.allFinite();
  };

  const size_t n_obs = obs.size();
  std::vector<double> rho(n_obs), zhat(n_obs), s2(n_obs);
  for (size_t i = 0; i < n_obs; ++i) {
    rho[i] = obs[i].z_m;
    zhat[i] = obs[i].z_m;
    s2[i] = obs[i].sigma_d_m * obs[i].sigma_d_m + obs[i].cov_p_RinG_m2.trace() / 3.0;
  }
  Eigen::VectorXd x;
  if (!solveOnce(rho, zhat, s2, x)) {
    sol.reason = "linear system rank deficient (" + std::to_string(sol.n_rows) + " difference rows for " +
                 std::to_string(u) + " unknowns)";
    return sol;
  }

  auto toParams = [&](const Eigen::VectorXd& v) {
    AnchorParams p = pb.priorParams(v.head<3>());
    for (int s = 0; s < n_slots; ++s)
      if (lin_col[static_cast<size_t>(s)] >= 0) p.gamma_m[static_cast<size_t>(s)] = v(lin_col[static_cast<size_t>(s)]);
    return p;
  };

  if (options_.linear_bias_correction) {
    for (int pass = 0; pass < std::max(1, options_.linear_passes); ++pass) {
      const AnchorParams cur = toParams(x);
      for (int s = 0; s < n_slots; ++s) {
        if (lin_col[static_cast<size_t>(s)] < 0) continue;
        for (int i : per_slot[static_cast<size_t>(s)]) {
          const double d = (cur.p_AinG - obs[static_cast<size_t>(i)].p_RinG).norm();
          rho[static_cast<size_t>(i)] = d;
          zhat[static_cast<size_t>(i)] = d + cur.gamma_m[static_cast<size_t>(s)];
          const double se = effectiveSigma(pb, cur, i);
          s2[static_cast<size_t>(i)] = se * se;
        }
      }
      Eigen::VectorXd x2;
      if (!solveOnce(rho, zhat, s2, x2)) break;  // keep the previous pass
      x = x2;
    }
  }

  sol.params = toParams(x);
  // Stationary references (and moving ones without rows): γ from the mean residual.
  for (int s = 0; s < n_slots; ++s) {
    if (lin_col[static_cast<size_t>(s)] >= 0) continue;
    const auto& idx = per_slot[static_cast<size_t>(s)];
    if (idx.empty()) continue;
    double sum = 0.0;
    const double beta = sol.params.beta[static_cast<size_t>(s)];
    for (int i : idx)
      sum += obs[static_cast<size_t>(i)].z_m - beta * (sol.params.p_AinG - obs[static_cast<size_t>(i)].p_RinG).norm();
    sol.params.gamma_m[static_cast<size_t>(s)] = sum / static_cast<double>(idx.size());
  }
  sol.ok = true;
  return sol;
}

}  // namespace meshnav::calib
