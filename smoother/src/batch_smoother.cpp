/// @file batch_smoother.cpp
/// @brief The batch smoother's costs and solve (batch_smoother.h). The only translation unit of
/// the smoother with Ceres templates.

#include "smoother/batch_smoother.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "estimator/core/nlos_mixture.h"
#include "estimator/core/so3.h"

namespace meshnav::smoother {

namespace {

template <class T>
using Vec3 = Eigen::Matrix<T, 3, 1>;
template <class T>
using Quat = Eigen::Quaternion<T>;

/// Exp(φ) as a quaternion, safe for Jets at φ = 0.
template <class T>
Quat<T> expQ(const Vec3<T>& phi) {
  T wxyz[4];
  ceres::AngleAxisToQuaternion(phi.data(), wxyz);
  return Quat<T>(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
}

/// Log(q) (rotation vector, angle in [0, π]).
template <class T>
Vec3<T> logQ(const Quat<T>& q) {
  const T s = q.w() < T(0) ? T(-1) : T(1);
  const T wxyz[4] = {s * q.w(), s * q.x(), s * q.y(), s * q.z()};
  Vec3<T> phi;
  ceres::QuaternionToAngleAxis(wxyz, phi.data());
  return phi;
}

/// Unit quaternion (Eigen storage x, y, z, w) with the local perturbation q ⊞ δ = q ⊗ Exp(δ): its
/// tangent is the filter's local orientation error δθ (R = R̂ Exp(δθ)).
struct LocalQuaternionPlus {
  template <class T>
  bool Plus(const T* x, const T* delta, T* x_plus_delta) const {
    Eigen::Map<const Quat<T>> q(x);
    Eigen::Map<Quat<T>> out(x_plus_delta);
    out = (q * expQ<T>(Vec3<T>(delta[0], delta[1], delta[2]))).normalized();
    return true;
  }
  template <class T>
  bool Minus(const T* y, const T* x, T* y_minus_x) const {
    Eigen::Map<const Quat<T>> qy(y), qx(x);
    const Vec3<T> d = logQ<T>(qx.conjugate() * qy);
    for (int i = 0; i < 3; ++i) y_minus_x[i] = d[i];
    return true;
  }
};

/// Upper-triangular U with Uᵀ U = Σ⁻¹ (whitening of a residual of covariance Σ).
template <int N>
Eigen::Matrix<double, N, N> sqrtInformation(const Eigen::Matrix<double, N, N>& cov) {
  const Eigen::Matrix<double, N, N> info = cov.inverse();
  const Eigen::Matrix<double, N, N> sym = 0.5 * (info + info.transpose());
  Eigen::LLT<Eigen::Matrix<double, N, N>> llt(sym);
  if (llt.info() != Eigen::Success) throw std::runtime_error("smoother: a covariance is not positive definite");
  return llt.matrixU();
}

/// The pose of I at t = t_k + τ from knot k's state and the increments over [t_k, t] (biases
/// corrected to first order): p_t = p_k + v_k τ + ½ g τ² + R_k (Δp + …), R_t = R_k ΔR Exp(J_R^ω δb_ω).
template <class T>
void poseFromKnot(const ImuIncrement& inc, const Eigen::Vector3d& g, const T* pk, const T* qk, const T* vk,
                  const T* bgk, const T* bak, Vec3<T>* p_t, Quat<T>* R_t) {
  Eigen::Map<const Vec3<T>> P(pk), V(vk), Bg(bgk), Ba(bak);
  Eigen::Map<const Quat<T>> Q(qk);
  const Vec3<T> dbg = Bg - inc.bg_lin.cast<T>();
  const Vec3<T> dba = Ba - inc.ba_lin.cast<T>();
  const T tau = T(inc.dt_s);
  *p_t = P + V * tau + T(0.5) * g.cast<T>() * tau * tau +
         Q * (inc.dp.cast<T>() + inc.dp_dbg.cast<T>() * dbg + inc.dp_dba.cast<T>() * dba);
  *R_t = Q * Quat<T>(Eigen::Quaterniond(inc.dR).cast<T>()) * expQ<T>(inc.dR_dbg.cast<T>() * dbg);
}

/// IMU increments between two knots (file comment of batch_smoother.h).
struct ImuCost {
  ImuIncrement inc;
  Eigen::Vector3d g;
  Eigen::Matrix<double, 9, 9> U;  ///< whitening incl. the noise scale

  template <class T>
  bool operator()(const T* pi, const T* qi, const T* vi, const T* bgi, const T* bai, const T* pj, const T* qj,
                  const T* vj, T* res) const {
    Eigen::Map<const Vec3<T>> Pi(pi), Vi(vi), Bg(bgi), Ba(bai), Pj(pj), Vj(vj);
    Eigen::Map<const Quat<T>> Qi(qi), Qj(qj);
    const Vec3<T> dbg = Bg - inc.bg_lin.cast<T>();
    const Vec3<T> dba = Ba - inc.ba_lin.cast<T>();
    const Quat<T> dR = Quat<T>(Eigen::Quaterniond(inc.dR).cast<T>()) * expQ<T>(inc.dR_dbg.cast<T>() * dbg);
    const T dt = T(inc.dt_s);
    const Vec3<T> gT = g.cast<T>();
    Eigen::Matrix<T, 9, 1> r;
    r.template segment<3>(0) = logQ<T>(dR.conjugate() * Qi.conjugate() * Qj);
    r.template segment<3>(3) = Qi.conjugate() * (Vj - Vi - gT * dt) -
                               (inc.dv.cast<T>() + inc.dv_dbg.cast<T>() * dbg + inc.dv_dba.cast<T>() * dba);
    r.template segment<3>(6) = Qi.conjugate() * (Pj - Pi - Vi * dt - T(0.5) * gT * dt * dt) -
                               (inc.dp.cast<T>() + inc.dp_dbg.cast<T>() * dbg + inc.dp_dba.cast<T>() * dba);
    Eigen::Map<Eigen::Matrix<T, 9, 1>> out(res);
    out = U.cast<T>() * r;
    return true;
  }
};

/// Bias random walk between two knots.
struct BiasWalkCost {
  double w_g, w_a;  ///< 1/σ of the walk over the span for b_ω and b_a
  template <class T>
  bool operator()(const T* bgi, const T* bai, const T* bgj, const T* baj, T* res) const {
    for (int k = 0; k < 3; ++k) {
      res[k] = T(w_g) * (bgj[k] - bgi[k]);
      res[3 + k] = T(w_a) * (baj[k] - bai[k]);
    }
    return true;
  }
};

/// A range between knots (file comment of batch_smoother.h).
struct RangeCost {
  ImuIncrement inc;  ///< over [t_k, t]
  Eigen::Vector3d g, p_TinI;
  double z, beta, gamma_fixed, inv_sigma;
  template <class T>
  bool operator()(const T* pk, const T* qk, const T* vk, const T* bgk, const T* bak, const T* gu, const T* cu,
                  const T* pa, T* res) const {
    Vec3<T> p_t;
    Quat<T> R_t;
    poseFromKnot(inc, g, pk, qk, vk, bgk, bak, &p_t, &R_t);
    const Vec3<T> p_T = p_t + R_t * p_TinI.cast<T>();
    const T d = (Eigen::Map<const Vec3<T>>(pa) - p_T).norm();
    res[0] = (T(z) - T(gamma_fixed) - gu[0] - cu[0] - T(beta) * d) * T(inv_sigma);
    return true;
  }
};

/// A downward rangefinder reading between knots (SmootherHeight), from knot k like a range.
struct HeightCost {
  ImuIncrement inc;
  Eigen::Vector3d g, p_IH;
  double h, inv_sigma;
  bool tilt_correction;
  template <class T>
  bool operator()(const T* pk, const T* qk, const T* vk, const T* bgk, const T* bak, const T* bh, T* res) const {
    Vec3<T> p_t;
    Quat<T> R_t;
    poseFromKnot(inc, g, pk, qk, vk, bgk, bak, &p_t, &R_t);
    const Vec3<T> s = p_t + R_t * p_IH.cast<T>();
    const T c = tilt_correction ? (R_t * Vec3<T>(T(0), T(0), T(1)))[2] : T(1);
    res[0] = (T(h) - s[2] / c - bh[0]) * T(inv_sigma);
    return true;
  }
};

/// An anchor–anchor range (the mesh): both positions are parameter blocks, one may be constant.
struct AnchorRangeCost {
  double z, beta, gamma_fixed, inv_sigma;
  template <class T>
  bool operator()(const T* pa, const T* pb, const T* gu, T* res) const {
    const T d = (Eigen::Map<const Vec3<T>>(pa) - Eigen::Map<const Vec3<T>>(pb)).norm();
    res[0] = (T(z) - T(gamma_fixed) - gu[0] - T(beta) * d) * T(inv_sigma);
    return true;
  }
};

/// Gaussian prior on a pose.
struct PosePriorCost {
  Eigen::Vector3d p0;
  Eigen::Quaterniond q0;
  Eigen::Matrix<double, 6, 6> U;
  template <class T>
  bool operator()(const T* p, const T* q, T* res) const {
    Eigen::Map<const Vec3<T>> P(p);
    Eigen::Map<const Quat<T>> Q(q);
    Eigen::Matrix<T, 6, 1> r;
    r.template head<3>() = P - p0.cast<T>();
    r.template tail<3>() = logQ<T>(Quat<T>(q0.cast<T>()).conjugate() * Q);
    Eigen::Map<Eigen::Matrix<T, 6, 1>> out(res);
    out = U.cast<T>() * r;
    return true;
  }
};

/// A resting body does not turn: Log(R_iᵀ R_j) ~ N(0, σ² I).
struct NoTurnCost {
  double inv_sigma;
  template <class T>
  bool operator()(const T* qi, const T* qj, T* res) const {
    Eigen::Map<const Quat<T>> Qi(qi), Qj(qj);
    const Vec3<T> d = logQ<T>(Qi.conjugate() * Qj);
    for (int k = 0; k < 3; ++k) res[k] = d[k] * T(inv_sigma);
    return true;
  }
};

/// Independent Gaussian prior on N values.
template <int N>
struct VectorPriorCost {
  Eigen::Matrix<double, N, 1> mean;
  double inv_sigma;
  template <class T>
  bool operator()(const T* x, T* res) const {
    for (int k = 0; k < N; ++k) res[k] = (x[k] - T(mean[k])) * T(inv_sigma);
    return true;
  }
};

/// The parameter blocks of one knot.
struct KnotBlocks {
  std::array<double, 3> p, v, bg, ba;
  std::array<double, 4> q;  ///< x, y, z, w
};

KnotBlocks toBlocks(const NavState& x) {
  KnotBlocks b;
  for (int k = 0; k < 3; ++k) {
    b.p[k] = x.p_IinG[k];
    b.v[k] = x.v_IinG[k];
    b.bg[k] = x.bias_gyro_rad_s[k];
    b.ba[k] = x.bias_acc_m_s2[k];
  }
  const Eigen::Quaterniond q = x.q_ItoG.normalized();
  b.q = {q.x(), q.y(), q.z(), q.w()};
  return b;
}

NavState fromBlocks(const KnotBlocks& b, Timestamp t) {
  NavState x;
  x.t = t;
  x.p_IinG = Eigen::Vector3d(b.p.data());
  x.v_IinG = Eigen::Vector3d(b.v.data());
  x.bias_gyro_rad_s = Eigen::Vector3d(b.bg.data());
  x.bias_acc_m_s2 = Eigen::Vector3d(b.ba.data());
  x.q_ItoG = Eigen::Quaterniond(b.q[3], b.q[0], b.q[1], b.q[2]).normalized();
  return x;
}

/// Index of the knot at or before `t` (the first when t precedes it).
size_t knotBefore(const std::vector<NavState>& knots, Timestamp t) {
  const auto it = std::upper_bound(knots.begin(), knots.end(), t,
                                   [](Timestamp x, const NavState& k) { return x < k.t; });
  return it == knots.begin() ? 0 : static_cast<size_t>(it - knots.begin()) - 1;
}

void checkProblem(const SmoothingProblem& pr) {
  if (pr.knots.size() < 2) throw std::invalid_argument("smoother: fewer than two knots");
  for (size_t k = 1; k < pr.knots.size(); ++k)
    if (!(pr.knots[k - 1].t < pr.knots[k].t)) throw std::invalid_argument("smoother: knot times not increasing");
  if (pr.imu.empty() || pr.imu.front().t > pr.knots.front().t || pr.imu.back().t < pr.knots.back().t)
    throw std::invalid_argument("smoother: the IMU samples do not cover the knots");
  for (const auto& r : pr.ranges) {
    if (r.anchor_unknown >= static_cast<int>(pr.anchors.size()) ||
        r.anchor_b_unknown >= static_cast<int>(pr.anchors.size()))
      throw std::invalid_argument("smoother: a range refers to an anchor that is not in the problem");
    if (r.gamma_unknown >= static_cast<int>(pr.range_biases.size()) ||
        r.common_unknown >= static_cast<int>(pr.range_biases.size()))
      throw std::invalid_argument("smoother: a range refers to a bias that is not in the problem");
    if (!(r.sigma_m > 0.0)) throw std::invalid_argument("smoother: a range has no positive sigma");
  }
}

}  // namespace

SmootherResult BatchSmoother::solve(const SmoothingProblem& pr,
                                    const std::function<void(int, int, const std::string&)>& progress) const {
  checkProblem(pr);
  if (!(options_.nlos_fraction >= 0.0 && options_.nlos_fraction < 1.0 && options_.nlos_offset_m >= 0.0 &&
        options_.nlos_scale_m > 0.0))
    throw std::invalid_argument("smoother: nlos_fraction must be in [0, 1), nlos_offset_m >= 0, nlos_scale_m > 0");
  const size_t n = pr.knots.size();
  std::vector<KnotBlocks> blocks;
  blocks.reserve(n);
  for (const auto& k : pr.knots) blocks.push_back(toBlocks(k));
  std::vector<double> biases;
  for (const auto& b : pr.range_biases) biases.push_back(b.prior_mean_m);
  double zero_gamma = 0.0, zero_common = 0.0, height_bias = 0.0;
  std::vector<std::array<double, 3>> anchor_blocks;
  for (const auto& a : pr.anchors) anchor_blocks.push_back({a.p_AinG.x(), a.p_AinG.y(), a.p_AinG.z()});
  SmootherResult result;
  const double k_loss = options_.loss_scale_sigmas;
  /// The loss on a residual whitened by σ_eff = `inflation` × the measurement's own σ: its scale
  /// stays k own-σ's.
  auto robustLoss = [&](double inflation = 1.0) -> ceres::LossFunction* {
    const double k = k_loss / inflation;
    if (options_.range_loss == BatchSmootherOptions::Loss::Cauchy) return new ceres::CauchyLoss(k);
    return new ceres::HuberLoss(k);
  };
  // The NLOS mixture's E step (batch_smoother.h): per range of the problem the factor 1/w on its
  // variance, from the previous pass's residual; 1 in the first pass and with ε = 0.
  const bool mixture = options_.nlos_fraction > 0.0;
  std::vector<double> nlos_variance_factor(pr.ranges.size(), 1.0);

  for (int pass = 0; pass < std::max(1, options_.passes); ++pass) {
    ceres::AutoDiffManifold<LocalQuaternionPlus, 4, 3> quat_manifold;  // outlives the problem
    ceres::Problem::Options popt;
    popt.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(popt);
    for (auto& b : blocks) {
      problem.AddParameterBlock(b.p.data(), 3);
      problem.AddParameterBlock(b.q.data(), 4, &quat_manifold);
      problem.AddParameterBlock(b.v.data(), 3);
      problem.AddParameterBlock(b.bg.data(), 3);
      problem.AddParameterBlock(b.ba.data(), 3);
    }
    // IMU increments at the current biases, and the bias walk.
    std::vector<ceres::ResidualBlockId> imu_ids;
    for (size_t k = 0; k + 1 < n; ++k) {
      const NavState xk = fromBlocks(blocks[k], pr.knots[k].t);
      auto* cost = new ImuCost;
      cost->inc = preintegrate(pr.imu, pr.knots[k].t, pr.knots[k + 1].t, xk.bias_gyro_rad_s, xk.bias_acc_m_s2,
                               pr.imu_noise);
      cost->g = pr.gravity_G;
      cost->U = sqrtInformation<9>(cost->inc.cov + 1e-15 * Eigen::Matrix<double, 9, 9>::Identity());
      KnotBlocks& a = blocks[k];
      KnotBlocks& b = blocks[k + 1];
      imu_ids.push_back(problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<ImuCost, 9, 3, 4, 3, 3, 3, 3, 4, 3>(cost), nullptr, a.p.data(), a.q.data(),
          a.v.data(), a.bg.data(), a.ba.data(), b.p.data(), b.q.data(), b.v.data()));
      const double dt = cost->inc.dt_s;
      auto* walk = new BiasWalkCost{1.0 / (pr.gyro_bias_rw * std::sqrt(dt)), 1.0 / (pr.acc_bias_rw * std::sqrt(dt))};
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<BiasWalkCost, 6, 3, 3, 3, 3>(walk), nullptr,
                               a.bg.data(), a.ba.data(), b.bg.data(), b.ba.data());
    }
    // Priors of the first knot.
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<VectorPriorCost<3>, 3, 3>(
                                 new VectorPriorCost<3>{Eigen::Vector3d::Zero(), 1.0 / pr.gyro_bias_sigma}),
                             nullptr, blocks[0].bg.data());
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<VectorPriorCost<3>, 3, 3>(
                                 new VectorPriorCost<3>{Eigen::Vector3d::Zero(), 1.0 / pr.acc_bias_sigma}),
                             nullptr, blocks[0].ba.data());
    if (pr.first_pose_prior) {
      Eigen::Matrix<double, 6, 6> cov = Eigen::Matrix<double, 6, 6>::Zero();
      cov.topLeftCorner<3, 3>() = pr.first_pose_prior->cov_p_m2;
      cov.bottomRightCorner<3, 3>() = pr.first_pose_prior->cov_theta_rad2;
      auto* prior = new PosePriorCost{pr.first_pose_prior->p_IinG, pr.first_pose_prior->q_ItoG,
                                      sqrtInformation<6>(cov + 1e-12 * Eigen::Matrix<double, 6, 6>::Identity())};
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PosePriorCost, 6, 3, 4>(prior), nullptr,
                               blocks[0].p.data(), blocks[0].q.data());
    }
    // Rest (landed) knots.
    if (pr.at_rest.size() == n) {
      for (size_t k = 0; k < n; ++k) {
        if (!pr.at_rest[k]) continue;
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<VectorPriorCost<3>, 3, 3>(
                                     new VectorPriorCost<3>{Eigen::Vector3d::Zero(), 1.0 / pr.rest_sigma_vel_m_s}),
                                 nullptr, blocks[k].v.data());
        if (k + 1 < n && pr.at_rest[k + 1]) {
          const double dt = (pr.knots[k + 1].t - pr.knots[k].t).sec();
          problem.AddResidualBlock(new ceres::AutoDiffCostFunction<NoTurnCost, 3, 4, 4>(
                                       new NoTurnCost{1.0 / (pr.rest_sigma_rate_rad_s * dt)}),
                                   nullptr, blocks[k].q.data(), blocks[k + 1].q.data());
        }
      }
    }
    // Range biases.
    problem.AddParameterBlock(&zero_gamma, 1);
    problem.AddParameterBlock(&zero_common, 1);
    problem.SetParameterBlockConstant(&zero_gamma);
    problem.SetParameterBlockConstant(&zero_common);
    for (size_t i = 0; i < biases.size(); ++i) {
      problem.AddParameterBlock(&biases[i], 1);
      Eigen::Matrix<double, 1, 1> mean;
      mean << pr.range_biases[i].prior_mean_m;
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<VectorPriorCost<1>, 1, 1>(
                                   new VectorPriorCost<1>{mean, 1.0 / pr.range_biases[i].prior_sigma_m}),
                               nullptr, &biases[i]);
    }
    // A measurement at t is tied to the knot k before it by the increments over [t_k, t], integrated
    // at that knot's current biases.
    auto incrementTo = [&](Timestamp t, size_t* k) {
      *k = knotBefore(pr.knots, t);
      const NavState xk = fromBlocks(blocks[*k], pr.knots[*k].t);
      return preintegrate(pr.imu, pr.knots[*k].t, t, xk.bias_gyro_rad_s, xk.bias_acc_m_s2, pr.imu_noise);
    };
    // Heights, with their bias b_H.
    if (!pr.heights.empty()) {
      problem.AddParameterBlock(&height_bias, 1);
      Eigen::Matrix<double, 1, 1> zero = Eigen::Matrix<double, 1, 1>::Zero();
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<VectorPriorCost<1>, 1, 1>(
                                   new VectorPriorCost<1>{zero, 1.0 / pr.height_bias_sigma_m}),
                               nullptr, &height_bias);
      for (const auto& h : pr.heights) {
        if (h.t < pr.knots.front().t || h.t > pr.knots.back().t) continue;
        size_t k = 0;
        auto* cost = new HeightCost;
        cost->inc = incrementTo(h.t, &k);
        cost->g = pr.gravity_G;
        cost->p_IH = pr.p_IH;
        cost->h = h.range_m;
        cost->inv_sigma = 1.0 / h.sigma_m;
        cost->tilt_correction = pr.height_tilt_correction;
        ceres::LossFunction* loss = robustLoss();
        KnotBlocks& b = blocks[k];
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<HeightCost, 1, 3, 4, 3, 3, 3, 1>(cost), loss,
                                 b.p.data(), b.q.data(), b.v.data(), b.bg.data(), b.ba.data(), &height_bias);
      }
    }
    // Anchors: an estimated one's block is shared by its ranges, a known one's is constant (a map's
    // elements stay where they are, as Ceres needs of a parameter block).
    for (size_t i = 0; i < anchor_blocks.size(); ++i) {
      problem.AddParameterBlock(anchor_blocks[i].data(), 3);
      if (pr.anchors[i].prior_sigma_m > 0.0)
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<VectorPriorCost<3>, 3, 3>(new VectorPriorCost<3>{
                                     pr.anchors[i].prior_mean_m, 1.0 / pr.anchors[i].prior_sigma_m}),
                                 nullptr, anchor_blocks[i].data());
    }
    std::map<SensorId, std::array<double, 3>> known_blocks;
    auto anchorBlock = [&](SensorId id, const Eigen::Vector3d& p, int unknown) -> double* {
      if (unknown >= 0) return anchor_blocks[static_cast<size_t>(unknown)].data();
      auto [it, fresh] = known_blocks.emplace(id, std::array<double, 3>{p.x(), p.y(), p.z()});
      if (fresh) {
        problem.AddParameterBlock(it->second.data(), 3);
        problem.SetParameterBlockConstant(it->second.data());
      }
      return it->second.data();
    };
    // Ranges.
    std::vector<ceres::ResidualBlockId> range_ids;
    std::vector<double> range_sigma, range_inflation;  // σ_eff and σ_eff / own σ of each block
    std::vector<size_t> range_index;                   // its range in pr.ranges
    for (size_t i = 0; i < pr.ranges.size(); ++i) {
      const SmootherRange& r = pr.ranges[i];
      if (r.t < pr.knots.front().t || r.t > pr.knots.back().t) continue;
      // σ²/w for the mixture's weight w; the loss keeps its scale at k of the range's own σ.
      const double sqrt_nlos = std::sqrt(nlos_variance_factor[i]);
      const double sigma_eff = r.sigma_m * sqrt_nlos, inflation = r.noise_inflation * sqrt_nlos;
      range_index.push_back(i);
      double* gu = r.gamma_unknown >= 0 ? &biases[static_cast<size_t>(r.gamma_unknown)] : &zero_gamma;
      if (r.tag == 0) {  // anchor–anchor
        auto* cost = new AnchorRangeCost{r.z_m, r.beta, r.gamma_fixed_m, 1.0 / sigma_eff};
        range_ids.push_back(problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<AnchorRangeCost, 1, 3, 3, 1>(cost), robustLoss(inflation),
            anchorBlock(r.anchor, r.p_AinG, r.anchor_unknown), anchorBlock(r.anchor_b, r.p_BinG, r.anchor_b_unknown),
            gu));
        range_sigma.push_back(sigma_eff);
        range_inflation.push_back(inflation);
        continue;
      }
      size_t k = 0;
      auto* cost = new RangeCost;
      cost->inc = incrementTo(r.t, &k);
      cost->g = pr.gravity_G;
      cost->p_TinI = r.p_TinI;
      cost->z = r.z_m;
      cost->beta = r.beta;
      cost->gamma_fixed = r.gamma_fixed_m;
      cost->inv_sigma = 1.0 / sigma_eff;
      ceres::LossFunction* loss = robustLoss(inflation);
      double* cu = r.common_unknown >= 0 ? &biases[static_cast<size_t>(r.common_unknown)] : &zero_common;
      KnotBlocks& b = blocks[k];
      range_ids.push_back(problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<RangeCost, 1, 3, 4, 3, 3, 3, 1, 1, 3>(cost), loss, b.p.data(), b.q.data(),
          b.v.data(), b.bg.data(), b.ba.data(), gu, cu, anchorBlock(r.anchor, r.p_AinG, r.anchor_unknown)));
      range_sigma.push_back(sigma_eff);
      range_inflation.push_back(inflation);
    }

    ceres::Solver::Options sopt;
    sopt.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    sopt.max_num_iterations = options_.max_iterations;
    sopt.num_threads = std::max(1, options_.threads);
    sopt.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(sopt, &problem, &summary);
    result.converged = summary.termination_type == ceres::CONVERGENCE;
    result.message = summary.BriefReport();

    // The IMU's and the ranges' residual statistics at this solution.
    double chi2_imu = 0.0;
    for (auto id : imu_ids) {
      double cost = 0.0;
      problem.EvaluateResidualBlock(id, false, &cost, nullptr, nullptr);
      chi2_imu += 2.0 * cost;
    }
    const double mean_chi2 = imu_ids.empty() ? 1.0 : chi2_imu / (9.0 * static_cast<double>(imu_ids.size()));
    result.n_ranges = static_cast<int>(range_ids.size());
    result.n_range_outliers = 0;
    result.n_range_nlos = 0;
    const bool last = pass + 1 >= std::max(1, options_.passes);
    double sq = 0.0;
    int n_in = 0;
    for (size_t i = 0; i < range_ids.size(); ++i) {
      double res = 0.0;
      problem.EvaluateResidualBlock(range_ids[i], false, nullptr, &res, nullptr);
      if (mixture) {
        // E step at this solution: r = z − ẑ [m], s = the range's own σ² (correlation and the
        // previous weight left out), for the next pass.
        double& factor = nlos_variance_factor[range_index[i]];
        if (factor > 2.0) ++result.n_range_nlos;  // this solve took it with w < 0.5
        if (!last) {
          const double own_sigma = range_sigma[i] / range_inflation[i];
          factor = estimator::nlos::innovationInflation(res * range_sigma[i], own_sigma * own_sigma,
                                                        options_.nlos_fraction, options_.nlos_offset_m,
                                                        options_.nlos_scale_m);
        }
      }
      if (std::abs(res) * range_inflation[i] > 3.0 * k_loss) {  // beyond 3 loss scales of its own σ
        ++result.n_range_outliers;
      } else {
        ++n_in;
        sq += res * res * range_sigma[i] * range_sigma[i];
      }
    }
    result.range_rms_inliers_m = n_in > 0 ? std::sqrt(sq / n_in) : 0.0;
    result.imu_chi2_per_dof = mean_chi2;

    if (progress) {
      std::ostringstream s;
      s << "pass " << pass + 1 << ": " << summary.iterations.size() << " iterations, cost " << summary.final_cost
        << ", IMU residual chi2/dof " << mean_chi2 << ", " << result.n_range_outliers
        << " of " << result.n_ranges << " ranges beyond " << 3.0 * k_loss << " sigma";
      if (mixture) s << ", " << result.n_range_nlos << " taken as NLOS (w < 0.5)";
      progress(pass + 1, std::max(1, options_.passes), s.str());
    }

    if (last) {
      result.knots.resize(n);
      for (size_t k = 0; k < n; ++k) result.knots[k].x = fromBlocks(blocks[k], pr.knots[k].t);
      result.range_biases_m = biases;
      for (size_t i = 0; i < anchor_blocks.size(); ++i)
        result.anchors.push_back(SmoothedAnchor{pr.anchors[i].id, Eigen::Vector3d(anchor_blocks[i].data())});
      result.height_bias_m = height_bias;
      result.n_heights = static_cast<int>(pr.heights.size());
      if (options_.covariance) {
        ceres::Covariance::Options copt;
        copt.algorithm_type = ceres::SPARSE_QR;
        copt.num_threads = std::max(1, options_.threads);
        ceres::Covariance cov(copt);
        std::vector<std::pair<const double*, const double*>> want;
        for (auto& b : blocks) {
          want.emplace_back(b.p.data(), b.p.data());
          want.emplace_back(b.q.data(), b.q.data());
        }
        for (auto& a : anchor_blocks) want.emplace_back(a.data(), a.data());
        result.covariance_ok = cov.Compute(want, &problem);
        if (result.covariance_ok) {
          for (size_t k = 0; k < n; ++k) {
            Eigen::Matrix<double, 3, 3, Eigen::RowMajor> Cp, Cq;
            cov.GetCovarianceBlockInTangentSpace(blocks[k].p.data(), blocks[k].p.data(), Cp.data());
            cov.GetCovarianceBlockInTangentSpace(blocks[k].q.data(), blocks[k].q.data(), Cq.data());
            result.knots[k].cov_p_m2 = Cp;
            result.knots[k].cov_theta_rad2 = Cq;
          }
          for (size_t i = 0; i < anchor_blocks.size(); ++i) {
            Eigen::Matrix<double, 3, 3, Eigen::RowMajor> Ca;
            cov.GetCovarianceBlockInTangentSpace(anchor_blocks[i].data(), anchor_blocks[i].data(), Ca.data());
            result.anchors[i].cov_p_m2 = Ca;
          }
        } else {
          result.message += "; covariance: rank deficient (a direction the data does not fix)";
        }
      }
    }
  }
  return result;
}

SmoothedKnot stateAt(const std::vector<SmoothedKnot>& knots, const std::vector<ImuSample>& imu,
                     const Eigen::Vector3d& gravity_G, Timestamp t) {
  if (knots.empty()) throw std::invalid_argument("stateAt: no knots");
  auto it = std::upper_bound(knots.begin(), knots.end(), t,
                             [](Timestamp x, const SmoothedKnot& k) { return x < k.x.t; });
  const SmoothedKnot& k = it == knots.begin() ? knots.front() : *(it - 1);
  SmoothedKnot out = k;
  if (t <= k.x.t) return out;
  const ImuIncrement inc = preintegrate(imu, k.x.t, t, k.x.bias_gyro_rad_s, k.x.bias_acc_m_s2, ImuNoiseDensities{});
  const Eigen::Matrix3d R = k.x.q_ItoG.toRotationMatrix();
  const double tau = inc.dt_s;
  out.x.t = t;
  out.x.p_IinG = k.x.p_IinG + k.x.v_IinG * tau + 0.5 * gravity_G * tau * tau + R * inc.dp;
  out.x.v_IinG = k.x.v_IinG + gravity_G * tau + R * inc.dv;
  out.x.q_ItoG = Eigen::Quaterniond(R * inc.dR).normalized();
  return out;
}

}  // namespace meshnav::smoother
