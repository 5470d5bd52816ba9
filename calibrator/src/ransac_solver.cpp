#include "calibrator/ransac_solver.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace meshnav::calib {

int RansacSolver::classify(const CalibrationProblem& pb, const AnchorParams& h, std::vector<bool>& inliers,
                           double* truncated_cost) const {
  const auto& obs = pb.observations();
  inliers.assign(obs.size(), false);
  int count = 0;
  double cost = 0.0;
  std::vector<double> e;
  for (int s = 0; s < static_cast<int>(pb.slots().size()); ++s) {
    const auto& idx = pb.slots()[static_cast<size_t>(s)].obs;
    const double beta = h.beta[static_cast<size_t>(s)];
    e.resize(idx.size());
    for (size_t k = 0; k < idx.size(); ++k) {
      const auto& o = obs[static_cast<size_t>(idx[k])];
      e[k] = o.z_m - beta * (h.p_AinG - o.p_RinG).norm();
    }
    std::vector<double> tmp = e;
    auto mid = tmp.begin() + static_cast<long>(tmp.size() / 2);
    std::nth_element(tmp.begin(), mid, tmp.end());
    const double gamma = *mid;
    for (size_t k = 0; k < idx.size(); ++k) {
      const auto& o = obs[static_cast<size_t>(idx[k])];
      const double thr = options_.ransac_threshold_sigmas * (o.sigma_d_m + std::sqrt(o.cov_p_RinG_m2.trace() / 3.0));
      const double r = std::abs(e[k] - gamma);
      if (r < thr) {
        inliers[static_cast<size_t>(idx[k])] = true;
        ++count;
        cost += r * r;
      } else {
        cost += thr * thr;
      }
    }
  }
  if (truncated_cost) *truncated_cost = cost;
  return count;
}

RansacResult RansacSolver::run(const CalibrationProblem& pb, uint64_t seed) const {
  RansacResult res;
  // Moving references and the per-reference sample size.
  std::vector<int> moving;
  for (int s = 0; s < static_cast<int>(pb.slots().size()); ++s)
    if (pb.slots()[static_cast<size_t>(s)].moving && pb.slots()[static_cast<size_t>(s)].obs.size() >= 2)
      moving.push_back(s);
  if (moving.empty()) {
    res.reason = "no moving reference";
    return res;
  }
  const int g = static_cast<int>(moving.size());
  const int rows_needed = 3 + g + std::max(0, options_.ransac_rows_margin);
  const int rows_per_ref = std::max(2, (rows_needed + g - 1) / g);
  std::vector<int> m_per(moving.size());
  int m_total = 0;
  for (size_t k = 0; k < moving.size(); ++k) {
    m_per[k] = std::min<int>(2 * rows_per_ref, static_cast<int>(pb.slots()[static_cast<size_t>(moving[k])].obs.size()));
    m_total += m_per[k];
  }

  std::mt19937_64 rng(seed ^ (0x9E3779B97F4A7C15ULL * static_cast<uint64_t>(pb.anchorId())));
  std::vector<std::vector<int>> pools(moving.size());
  for (size_t k = 0; k < moving.size(); ++k) pools[k] = pb.slots()[static_cast<size_t>(moving[k])].obs;

  int best_count = -1;
  double best_cost = 0.0;
  std::vector<bool> best_inliers, cur;
  int n_iter = options_.ransac_max_iterations;
  const int n_used = pb.numUsed();
  std::vector<int> sample;
  int it = 0;
  for (; it < n_iter; ++it) {
    sample.clear();
    for (size_t k = 0; k < moving.size(); ++k) {
      auto& pool = pools[k];
      // Partial Fisher–Yates with our own index draw (portable, deterministic).
      for (int j = 0; j < m_per[k]; ++j) {
        const uint64_t span = pool.size() - static_cast<size_t>(j);
        const size_t pick = static_cast<size_t>(j) + static_cast<size_t>(rng() % span);
        std::swap(pool[static_cast<size_t>(j)], pool[pick]);
        sample.push_back(pool[static_cast<size_t>(j)]);
      }
    }
    const LinearSolution h = linear_.solve(pb, sample);
    if (!h.ok) continue;
    double cost = 0.0;
    const int count = classify(pb, h.params, cur, &cost);
    if (count > best_count || (count == best_count && cost < best_cost)) {
      best_count = count;
      best_cost = cost;
      best_inliers = cur;
      const double w = std::clamp(static_cast<double>(count) / std::max(1, n_used), 1e-6, 1.0 - 1e-12);
      const double p_good = std::pow(w, m_total);
      const double need = p_good >= 1.0 - 1e-12 ? 0.0
                                                 : std::log(1.0 - options_.ransac_confidence) / std::log(1.0 - p_good);
      n_iter = std::clamp(static_cast<int>(std::ceil(need)), options_.ransac_min_iterations, options_.ransac_max_iterations);
    }
  }
  res.iterations = it;
  if (best_count < 0) {
    res.reason = "no RANSAC hypothesis could be solved";
    return res;
  }
  std::vector<int> inlier_idx;
  for (int i = 0; i < static_cast<int>(best_inliers.size()); ++i)
    if (best_inliers[static_cast<size_t>(i)]) inlier_idx.push_back(i);
  res.solution = linear_.solve(pb, inlier_idx);
  if (!res.solution.ok) {
    res.reason = "linear fit on the RANSAC inliers failed: " + res.solution.reason;
    return res;
  }
  res.inliers = std::move(best_inliers);
  res.n_inliers = best_count;
  res.ok = true;
  return res;
}

}  // namespace meshnav::calib
