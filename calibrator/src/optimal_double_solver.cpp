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

namespace {

/// The linear system of the optimal double method for one problem and subset of observations:
/// unknowns [p (3), γ of each moving slot with ≥ 2 ranges], one row per pair of ranges of a slot.
struct DoubleSystem {
  const CalibrationProblem& pb;
  std::vector<std::vector<int>> per_slot;            ///< observations per slot, time order
  std::vector<int> lin_col;                          ///< column of the slot's γ (-1: not in the system)
  int u = 3;                                         ///< number of unknowns
  std::vector<std::vector<std::pair<int, int>>> pairs;  ///< the differenced pairs per slot

  int nSlots() const { return static_cast<int>(per_slot.size()); }
  const CalibObservation& obs(int i) const { return pb.observations()[static_cast<size_t>(i)]; }
};

/// σ² of a range with the reference's position uncertainty (before any estimate exists).
double priorSigma2(const CalibObservation& o) {
  return o.sigma_d_m * o.sigma_d_m + o.cov_p_RinG_m2.trace() / 3.0;
}

/// Observations per slot (time order = index order, the problem is time-sorted); `subset` empty:
/// all of them.
std::vector<std::vector<int>> observationsPerSlot(const CalibrationProblem& pb, const std::vector<int>& subset) {
  const size_t n_slots = pb.slots().size();
  std::vector<std::vector<int>> per_slot(n_slots);
  if (subset.empty()) {
    for (size_t s = 0; s < n_slots; ++s) per_slot[s] = pb.slots()[s].obs;
    return per_slot;
  }
  std::vector<int> sorted = subset;
  std::sort(sorted.begin(), sorted.end());
  for (int i : sorted)
    if (pb.slotOf(i) >= 0) per_slot[static_cast<size_t>(pb.slotOf(i))].push_back(i);
  return per_slot;
}

/// Column layout: a γ column for each moving slot with ≥ 2 ranges; sets sys.u.
void assignColumns(DoubleSystem& sys) {
  sys.lin_col.assign(sys.per_slot.size(), -1);
  sys.u = 3;
  for (int s = 0; s < sys.nSlots(); ++s)
    if (sys.pb.slots()[static_cast<size_t>(s)].moving && sys.per_slot[static_cast<size_t>(s)].size() >= 2)
      sys.lin_col[static_cast<size_t>(s)] = sys.u++;
}

/// Pass 1 pairing and regressors (ρ = z).
void choosePairs(DoubleSystem& sys) {
  sys.pairs.assign(sys.per_slot.size(), {});
  for (int s = 0; s < sys.nSlots(); ++s) {
    if (sys.lin_col[static_cast<size_t>(s)] < 0) continue;
    const auto& idx = sys.per_slot[static_cast<size_t>(s)];
    std::vector<double> rho, var_half;
    for (int i : idx) {
      const double z = std::max(sys.obs(i).z_m, kMinRange);
      rho.push_back(sys.obs(i).z_m);
      var_half.push_back(4.0 * priorSigma2(sys.obs(i)) * z * z);
    }
    sys.pairs[static_cast<size_t>(s)] = OptimalDoubleSolver::selectPairs(sys.pb, idx, rho, var_half);
  }
}

/// One weighted LS solve given the regressor ρ_i, the predicted range ẑ_i and σ²_i (for the
/// weights). `rows` gets the number of difference rows. False when rank deficient.
bool solveWeighted(const DoubleSystem& sys, const std::vector<double>& rho_all, const std::vector<double>& zhat_all,
                   const std::vector<double>& s2_all, Eigen::VectorXd& x, int& rows) {
  const int u = sys.u;
  Eigen::MatrixXd N = Eigen::MatrixXd::Zero(u, u);
  Eigen::VectorXd r = Eigen::VectorXd::Zero(u);
  rows = 0;
  for (int s = 0; s < sys.nSlots(); ++s) {
    const int col = sys.lin_col[static_cast<size_t>(s)];
    if (col < 0) continue;
    for (auto [i, j] : sys.pairs[static_cast<size_t>(s)]) {
      const auto& o1 = sys.obs(i);
      const auto& o2 = sys.obs(j);
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
  if (rows < u) return false;
  // Scale-invariant rank test on the normalised normal matrix.
  const Eigen::VectorXd dg = N.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd Nn = dg.asDiagonal() * N * dg.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Nn, Eigen::EigenvaluesOnly);
  if (!(es.eigenvalues()(0) > 1e-10 * es.eigenvalues()(u - 1))) return false;
  x = N.ldlt().solve(r);
  return x.allFinite();
}

/// The anchor parameters of a solution vector (γ of the slots outside the system: the prior).
AnchorParams toParams(const DoubleSystem& sys, const Eigen::VectorXd& v) {
  AnchorParams p = sys.pb.priorParams(v.head<3>());
  for (int s = 0; s < sys.nSlots(); ++s)
    if (sys.lin_col[static_cast<size_t>(s)] >= 0) p.gamma_m[static_cast<size_t>(s)] = v(sys.lin_col[static_cast<size_t>(s)]);
  return p;
}

/// Stationary references (and moving ones without rows): γ from the mean residual.
void gammaFromMeanResidual(const DoubleSystem& sys, AnchorParams& params) {
  for (int s = 0; s < sys.nSlots(); ++s) {
    if (sys.lin_col[static_cast<size_t>(s)] >= 0) continue;
    const auto& idx = sys.per_slot[static_cast<size_t>(s)];
    if (idx.empty()) continue;
    double sum = 0.0;
    const double beta = params.beta[static_cast<size_t>(s)];
    for (int i : idx) sum += sys.obs(i).z_m - beta * (params.p_AinG - sys.obs(i).p_RinG).norm();
    params.gamma_m[static_cast<size_t>(s)] = sum / static_cast<double>(idx.size());
  }
}

}  // namespace

LinearSolution OptimalDoubleSolver::solve(const CalibrationProblem& pb, const std::vector<int>& subset) const {
  LinearSolution sol;
  DoubleSystem sys{pb, observationsPerSlot(pb, subset), {}, 3, {}};
  assignColumns(sys);
  if (sys.u == 3) {
    sol.reason = "no moving reference with at least 2 ranges";
    return sol;
  }
  choosePairs(sys);

  const auto& obs = pb.observations();
  const size_t n_obs = obs.size();
  std::vector<double> rho(n_obs), zhat(n_obs), s2(n_obs);
  for (size_t i = 0; i < n_obs; ++i) {
    rho[i] = obs[i].z_m;
    zhat[i] = obs[i].z_m;
    s2[i] = priorSigma2(obs[i]);
  }
  Eigen::VectorXd x;
  if (!solveWeighted(sys, rho, zhat, s2, x, sol.n_rows)) {
    sol.reason = "linear system rank deficient (" + std::to_string(sol.n_rows) + " difference rows for " +
                 std::to_string(sys.u) + " unknowns)";
    return sol;
  }
  if (options_.linear_bias_correction) {
    // Re-solve with the regressor ρ = d(p̂) and the weights of the current estimate.
    for (int pass = 0; pass < std::max(1, options_.linear_passes); ++pass) {
      const AnchorParams cur = toParams(sys, x);
      for (int s = 0; s < sys.nSlots(); ++s) {
        if (sys.lin_col[static_cast<size_t>(s)] < 0) continue;
        for (int i : sys.per_slot[static_cast<size_t>(s)]) {
          const double d = (cur.p_AinG - obs[static_cast<size_t>(i)].p_RinG).norm();
          rho[static_cast<size_t>(i)] = d;
          zhat[static_cast<size_t>(i)] = d + cur.gamma_m[static_cast<size_t>(s)];
          const double se = effectiveSigma(pb, cur, i);
          s2[static_cast<size_t>(i)] = se * se;
        }
      }
      Eigen::VectorXd x2;
      if (!solveWeighted(sys, rho, zhat, s2, x2, sol.n_rows)) break;  // keep the previous pass
      x = x2;
    }
  }
  sol.params = toParams(sys, x);
  gammaFromMeanResidual(sys, sol.params);
  sol.ok = true;
  return sol;
}

}  // namespace meshnav::calib
