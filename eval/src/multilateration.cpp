#include "eval/multilateration.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace meshnav::eval {

std::optional<Eigen::Vector3d> Multilateration::linearSolution(const std::vector<Eigen::Vector3d>& a,
                                                               const std::vector<double>& z) {
  const int n = static_cast<int>(a.size());
  if (n < 4 || static_cast<int>(z.size()) != n) return std::nullopt;
  // ‖x‖² − 2 a_iᵀx + ‖a_i‖² = z_i²; subtracting the mean equation removes ‖x‖²:
  // −2 (a_i − ā)ᵀ x = (z_i² − mean z²) − (‖a_i‖² − mean ‖a‖²).
  Eigen::Vector3d a_mean = Eigen::Vector3d::Zero();
  double z2_mean = 0.0, a2_mean = 0.0;
  for (int i = 0; i < n; ++i) {
    a_mean += a[i];
    z2_mean += z[i] * z[i];
    a2_mean += a[i].squaredNorm();
  }
  a_mean /= n;
  z2_mean /= n;
  a2_mean /= n;
  Eigen::MatrixXd A(n, 3);
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) {
    A.row(i) = -2.0 * (a[i] - a_mean).transpose();
    b(i) = (z[i] * z[i] - z2_mean) - (a[i].squaredNorm() - a2_mean);
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd s = svd.singularValues();
  if (!(s(0) > 0.0) || s(2) < 1e-6 * s(0)) return std::nullopt;
  return Eigen::Vector3d(svd.solve(b));
}

std::optional<Eigen::Vector3d> Multilateration::solveEpoch(const std::vector<Eigen::Vector3d>& a,
                                                           const std::vector<double>& z, const Eigen::Vector3d& x0,
                                                           const char** reason) const {
  auto fail = [&](const char* why) -> std::optional<Eigen::Vector3d> {
    if (reason) *reason = why;
    return std::nullopt;
  };
  if (a.size() != z.size() || a.size() < 3) return fail("degenerate");
  Eigen::Vector3d x = x0;
  for (int it = 0; it < options_.max_iterations; ++it) {
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < a.size(); ++i) {
      const Eigen::Vector3d d = x - a[i];
      const double dist = std::max(d.norm(), 1e-9);
      const double r = dist - z[i];
      const double w = std::abs(r) <= options_.huber_k_m ? 1.0 : options_.huber_k_m / std::abs(r);
      const Eigen::Vector3d J = d / dist;
      H += w * J * J.transpose();
      g += w * J * r;
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(H);
    if (!(eig.eigenvalues()(0) > 1e-6 * std::max(eig.eigenvalues()(2), 1e-12))) return fail("degenerate");
    const Eigen::Vector3d dx = -H.ldlt().solve(g);
    x += dx;
    if (!x.allFinite()) return fail("degenerate");
    if (dx.norm() < 1e-9) break;
  }
  double sum_sq = 0.0;
  for (size_t i = 0; i < a.size(); ++i) sum_sq += std::pow((x - a[i]).norm() - z[i], 2);
  if (std::sqrt(sum_sq / static_cast<double>(a.size())) > options_.max_rms_residual_m) return fail("large_residual");
  return x;
}

std::vector<PoseEstimate> Multilateration::solve(const std::vector<RangeSample>& ranges, const SystemSetup& setup,
                                                 Diagnostics& diag, std::vector<SensorId>* fix_tags) {
  stats_ = Stats{};
  std::vector<std::pair<PoseEstimate, SensorId>> fixes;
  for (const auto& tag_entry : setup.rel_tag_positions) {
    const SensorId tag = tag_entry.first;
    // This tag's ranges to known anchors, in time order: (t, anchor id, range).
    std::vector<const RangeSample*> mine;
    for (const auto& r : ranges) {
      const bool ok = (r.id_initiator == tag && setup.isKnownAnchor(r.id_responder)) ||
                      (r.id_responder == tag && setup.isKnownAnchor(r.id_initiator));
      if (ok) mine.push_back(&r);
    }
    std::stable_sort(mine.begin(), mine.end(), [](const RangeSample* x, const RangeSample* y) { return x->t < y->t; });
    stats_.ranges_used += static_cast<int>(mine.size());
    std::optional<PoseEstimate> last;
    for (size_t i = 0; i < mine.size();) {
      const Timestamp t0 = mine[i]->t;
      std::map<SensorId, std::pair<Timestamp, double>> epoch;  // anchor → latest (t, z)
      for (; i < mine.size() && (mine[i]->t - t0).sec() <= options_.window_s; ++i) {
        const SensorId anchor = mine[i]->id_initiator == tag ? mine[i]->id_responder : mine[i]->id_initiator;
        epoch[anchor] = {mine[i]->t, mine[i]->range_m};
      }
      ++stats_.epochs;
      if (static_cast<int>(epoch.size()) < options_.min_anchors) {
        ++stats_.too_few_anchors;
        diag.count("multilateration:too_few_anchors");
        continue;
      }
      std::vector<Eigen::Vector3d> a;
      std::vector<double> z;
      int64_t t_sum_us = 0;
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (const auto& [id, tz] : epoch) {
        a.push_back(setup.abs_anchor_positions.at(id));
        z.push_back(tz.second);
        t_sum_us += tz.first.us - t0.us;
        centroid += a.back();
      }
      const Timestamp t{t0.us + t_sum_us / static_cast<int64_t>(epoch.size())};
      Eigen::Vector3d x0 = centroid / static_cast<double>(a.size());
      if (last && (t - last->t).sec() <= options_.reuse_fix_s) x0 = last->p_IinG;
      else if (auto lin = linearSolution(a, z)) x0 = *lin;
      const char* reason = "";
      const auto x = solveEpoch(a, z, x0, &reason);
      if (!x) {
        ++(std::string(reason) == "degenerate" ? stats_.degenerate : stats_.large_residual);
        diag.count(std::string("multilateration:") + reason);
        continue;
      }
      PoseEstimate fix;
      fix.t = t;
      fix.p_IinG = *x;
      fixes.emplace_back(fix, tag);
      last = fix;
      ++stats_.fixes;
    }
  }
  std::stable_sort(fixes.begin(), fixes.end(), [](const auto& x, const auto& y) { return x.first.t < y.first.t; });
  std::vector<PoseEstimate> out;
  out.reserve(fixes.size());
  if (fix_tags) fix_tags->clear();
  for (const auto& [fix, tag] : fixes) {
    out.push_back(fix);
    if (fix_tags) fix_tags->push_back(tag);
  }
  return out;
}

}  // namespace meshnav::eval
