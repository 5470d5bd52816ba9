/// @file factorized_covariance.cpp
/// @brief FactorizedCovariance, first part: instances, propagation, the general update with the DP
/// write-back, and the invariant check. The DAH update is in factorized_covariance_dah.cpp.

#include "estimator/filter/factorized_covariance.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <limits>
#include <stdexcept>
#include <string>

#include "estimator/core/imu_state.h"
#include "estimator/filter/dense_ekf_update.h"
#include "estimator/filter/factorized_covariance_internals.h"

namespace meshnav::estimator {

namespace {

using Eigen::MatrixXd;
using factorized_internal::roughCondition;
using factorized_internal::shared;

/// The true factor S_ij = L_i S̄_ij (null S̄: identity; empty L: identity).
MatrixXd trueFactor(const InstanceBelief& b, const FactorEntry& e) {
  if (!e.S_bar) return b.L.size() ? b.L : MatrixXd::Identity(b.dim, b.dim);
  if (e.S_bar == b.L_inv) return MatrixXd::Identity(b.dim, b.dim);
  return b.L.size() ? MatrixXd(b.L * *e.S_bar) : *e.S_bar;
}

/// The true factor S = L_i S̄ of one side of a pair into `out` (dimensions ≤ kMaxInstanceDim;
/// fixed-size kernels for the IMU's and an anchor's factor towards an anchor); false when it is the
/// identity (S̄ null and L_i empty, or S̄ the L_i⁻¹ of the current L_i).
bool trueFactorInto(const InstanceBelief& b, const FactorEntry& e, factorized_internal::InstMat& out) {
  if (!e.S_bar) {
    if (!b.L.size()) return false;
    out = b.L;
  } else if (e.S_bar == b.L_inv) {
    return false;
  } else if (!b.L.size()) {
    out = *e.S_bar;
  } else if (b.dim == ImuErr::kDim && e.S_bar->cols() == 3) {
    // Σ_IA factor of the IMU towards an anchor: fixed-size kernel.
    using M15 = Eigen::Matrix<double, ImuErr::kDim, ImuErr::kDim>;
    using M15x3 = Eigen::Matrix<double, ImuErr::kDim, 3>;
    out.resize(ImuErr::kDim, 3);
    Eigen::Map<M15x3>(out.data()).noalias() =
        Eigen::Map<const M15>(b.L.data()).lazyProduct(Eigen::Map<const M15x3>(e.S_bar->data()));
  } else if (b.dim == 3 && e.S_bar->cols() == 3) {
    out.resize(3, 3);
    Eigen::Map<Eigen::Matrix3d>(out.data()).noalias() =
        Eigen::Map<const Eigen::Matrix3d>(b.L.data()).lazyProduct(Eigen::Map<const Eigen::Matrix3d>(e.S_bar->data()));
  } else {
    out.noalias() = b.L * *e.S_bar;
  }
  return true;
}

}  // namespace

int FactorizedCovariance::index(SensorId id) const {
  const auto& bl = layout_.blocks();
  for (size_t k = 0; k < bl.size(); ++k)
    if (bl[k].id == id) return static_cast<int>(k);
  throw std::out_of_range("FactorizedCovariance: no instance " + std::to_string(id));
}

InstanceBelief& FactorizedCovariance::mut(int k) {
  auto& p = inst_[static_cast<size_t>(k)];
  if (p.use_count() > 1) p = std::make_shared<InstanceBelief>(*p);
  return *p;
}

FactorDictionary& FactorizedCovariance::mutDict(InstanceBelief& b) {
  if (b.factors.use_count() > 1) b.factors = std::make_shared<FactorDictionary>(*b.factors);
  return *b.factors;
}

void FactorizedCovariance::add(SensorId id, InstanceKind kind, const MatrixXd& cov, Timestamp t) {
  if (cov.rows() != cov.cols()) throw std::invalid_argument("FactorizedCovariance::add: covariance not square");
  layout_.add(id, kind, static_cast<int>(cov.rows()));  // throws if present
  auto b = std::make_shared<InstanceBelief>();
  b->id = id;
  b->kind = kind;
  b->dim = static_cast<int>(cov.rows());
  b->t = t;
  b->Sigma = 0.5 * (cov + cov.transpose());
  inst_.push_back(std::move(b));
}

bool FactorizedCovariance::remove(SensorId id) {
  if (!has(id)) return false;
  const int k = index(id);
  // The partners forget their factor towards `id` (the pair's correlation leaves with it).
  for (const FactorEntry& e : inst_[static_cast<size_t>(k)]->factors->entries()) {
    InstanceBelief& p = mut(index(e.partner));
    mutDict(p).erase(id);
  }
  inst_.erase(inst_.begin() + k);
  layout_.remove(id);
  leaveSet(id);
  return true;
}

void FactorizedCovariance::propagate(SensorId id, const Eigen::Ref<const MatrixXd>& Phi,
                                    const Eigen::Ref<const MatrixXd>& Q, Timestamp t) {
  InstanceBelief& b = mut(index(id));
  if (b.dim == 15 && Phi.rows() == 15) {
    // Fixed-size kernels for the IMU instance (the step run at the IMU rate).
    using M15 = Eigen::Matrix<double, 15, 15>;
    const Eigen::Map<const M15> F(Phi.data());
    Eigen::Map<M15> S(b.Sigma.data());
    M15 tmp = F * S;
    S.noalias() = tmp * F.transpose();
    S += Eigen::Map<const M15>(Q.data());
    tmp = 0.5 * (S + S.transpose());
    S = tmp;
    if (b.L.size()) {
      Eigen::Map<M15> L(b.L.data());
      tmp.noalias() = F * L;
      L = tmp;
    } else {
      b.L = Phi;
    }
  } else {
    b.Sigma = Phi * b.Sigma * Phi.transpose() + Q;
    b.Sigma = 0.5 * (b.Sigma + b.Sigma.transpose()).eval();
    b.L = b.L.size() ? MatrixXd(Phi * b.L) : MatrixXd(Phi);
  }
  b.L_inv.reset();
  b.t = t;
  if (++b.lazy_steps > kMaxLazySteps) renormalize(id);
}

void FactorizedCovariance::addNoise(SensorId id, const MatrixXd& Q, Timestamp t) {
  InstanceBelief& b = mut(index(id));
  b.Sigma += Q;
  b.t = t;
}

void FactorizedCovariance::renormalize(SensorId id) {
  InstanceBelief& b = mut(index(id));
  if (b.L.size() == 0) return;
  for (FactorEntry& e : mutDict(b).entries()) e.S_bar = shared(trueFactor(b, e));
  b.L.resize(0, 0);
  b.L_inv.reset();
  b.lazy_steps = 0;
  ++renormalizations_;
}

MatrixXd FactorizedCovariance::pairCov(int ki, int kj) const {
  MatrixXd C(inst_[static_cast<size_t>(ki)]->dim, inst_[static_cast<size_t>(kj)]->dim);
  pairCovInto(ki, kj, C);
  return C;
}

void FactorizedCovariance::pairCovInto(int ki, int kj, Eigen::Ref<MatrixXd> out) const {
  const InstanceBelief& bi = *inst_[static_cast<size_t>(ki)];
  const InstanceBelief& bj = *inst_[static_cast<size_t>(kj)];
  const FactorEntry* eij = bi.factors->find(bj.id);
  if (!eij) {
    out.setZero();
    return;
  }
  const FactorEntry* eji = bj.factors->find(bi.id);
  if (!eji) throw std::logic_error("FactorizedCovariance: factor of pair (" + std::to_string(bi.id) + ", " +
                                   std::to_string(bj.id) + ") present on one side only");
  // S_ij S_jiᵀ without multiplying identities (S = L S̄; a null S̄ or an empty L is the identity).
  if (bi.dim <= factorized_internal::kMaxInstanceDim && bj.dim <= factorized_internal::kMaxInstanceDim) {
    factorized_internal::InstMat A, B;  // stack storage
    const bool fa = trueFactorInto(bi, *eij, A), fb = trueFactorInto(bj, *eji, B);
    if (fa && fb)
      out.noalias() = A * B.transpose();
    else if (fa)
      out = A;
    else if (fb)
      out = B.transpose();
    else
      out.setIdentity();
    return;
  }
  MatrixXd scratch_i, scratch_j;
  auto factor = [](const InstanceBelief& b, const FactorEntry& e, MatrixXd& scratch) -> const MatrixXd* {
    if (!e.S_bar) return b.L.size() ? &b.L : nullptr;
    if (e.S_bar == b.L_inv) return nullptr;
    if (!b.L.size()) return e.S_bar.get();
    scratch.noalias() = b.L * *e.S_bar;
    return &scratch;
  };
  const MatrixXd* Si = factor(bi, *eij, scratch_i);
  const MatrixXd* Sj = factor(bj, *eji, scratch_j);
  if (Si && Sj)
    out.noalias() = *Si * Sj->transpose();
  else if (Si)
    out = *Si;
  else if (Sj)
    out = Sj->transpose();
  else
    out.setIdentity();
}

MatrixXd FactorizedCovariance::block(SensorId a, SensorId b) const {
  const int ka = index(a), kb = index(b);
  if (ka == kb) return inst_[static_cast<size_t>(ka)]->Sigma;
  return pairCov(ka, kb);
}

MatrixXd FactorizedCovariance::full() const {
  const auto& bl = layout_.blocks();
  MatrixXd P = MatrixXd::Zero(layout_.dim(), layout_.dim());
  for (size_t a = 0; a < bl.size(); ++a) {
    P.block(bl[a].offset, bl[a].offset, bl[a].dim, bl[a].dim) = inst_[a]->Sigma;
    for (const FactorEntry& e : inst_[a]->factors->entries()) {
      const int kb = index(e.partner);
      if (kb <= static_cast<int>(a)) continue;
      const MatrixXd C = pairCov(static_cast<int>(a), kb);
      const StateBlock& b = bl[static_cast<size_t>(kb)];
      P.block(bl[a].offset, b.offset, bl[a].dim, b.dim) = C;
      P.block(b.offset, bl[a].offset, b.dim, bl[a].dim) = C.transpose();
    }
  }
  return P;
}

FactorizedCovariance::Result FactorizedCovariance::update(const Linearization& lin, double nis_gate, Timestamp t) {
  if (mode_ == Mode::DAH) return updateDah(lin, nis_gate, t);
  // DP: every instance takes part.
  std::vector<int> part;
  for (int k = 0; k < static_cast<int>(inst_.size()); ++k) part.push_back(k);
  StateLayout sub;
  for (int k : part) {
    const StateBlock& b = layout_.blocks()[static_cast<size_t>(k)];
    sub.add(b.id, b.kind, b.dim);
  }
  // Stack Σ_PP: blocks Σ_ii and Σ_ij = S_ij S_jiᵀ.
  MatrixXd P(sub.dim(), sub.dim());
  const auto& sb = sub.blocks();
  for (size_t a = 0; a < part.size(); ++a) {
    P.block(sb[a].offset, sb[a].offset, sb[a].dim, sb[a].dim) = inst_[static_cast<size_t>(part[a])]->Sigma;
    for (size_t c = a + 1; c < part.size(); ++c) {
      auto C = P.block(sb[a].offset, sb[c].offset, sb[a].dim, sb[c].dim);
      pairCovInto(part[a], part[c], C);
      P.block(sb[c].offset, sb[a].offset, sb[c].dim, sb[a].dim) = C.transpose();
    }
  }
  DenseUpdateOutput out = denseEkfUpdate(P, sub, lin, nis_gate, joseph_);
  Result res;
  res.nis = out.nis;
  if (!out.accepted) return res;
  writeBackDp(part, sub, P, t);
  res.accepted = true;
  res.blocks = sub.blocks();
  res.dx = std::move(out.dx);
  return res;
}

void FactorizedCovariance::writeBackDp(const std::vector<int>& part, const StateLayout& sub, const MatrixXd& P,
                                       Timestamp t) {
  const auto& sb = sub.blocks();
  // Per instance: Σ_ii, L_i = I, and a new dictionary: S̄_ij = Σ_ij (smaller id), S̄_ji = I.
  std::vector<std::vector<FactorEntry>> dicts(part.size());
  for (size_t a = 0; a < part.size(); ++a) {
    for (size_t c = a + 1; c < part.size(); ++c) {
      const auto C = P.block(sb[a].offset, sb[c].offset, sb[a].dim, sb[c].dim);
      if (C.isZero(0.0)) continue;  // still uncorrelated
      if (sb[a].id < sb[c].id) {
        dicts[a].push_back({sb[c].id, shared(C)});
        dicts[c].push_back({sb[a].id, nullptr});
      } else {
        dicts[c].push_back({sb[a].id, shared(C.transpose())});
        dicts[a].push_back({sb[c].id, nullptr});
      }
    }
  }
  for (size_t a = 0; a < part.size(); ++a) {
    InstanceBelief& b = mut(part[a]);
    b.Sigma = P.block(sb[a].offset, sb[a].offset, sb[a].dim, sb[a].dim);
    b.L.resize(0, 0);
    b.L_inv.reset();
    b.lazy_steps = 0;
    b.t = t;
    std::sort(dicts[a].begin(), dicts[a].end(),
              [](const FactorEntry& x, const FactorEntry& y) { return x.partner < y.partner; });
    auto d = std::make_shared<FactorDictionary>();
    d->entries() = std::move(dicts[a]);
    b.factors = std::move(d);
  }
}

void FactorizedCovariance::checkInvariants(const char* where) const {
  auto fail = [&](const std::string& what) {
    throw std::logic_error(std::string("FactorizedCovariance (after ") + where + "): " + what);
  };
  const auto& bl = layout_.blocks();
  if (bl.size() != inst_.size()) fail("layout and instances differ");
  for (size_t a = 0; a < bl.size(); ++a) {
    const InstanceBelief& b = *inst_[a];
    if (b.id != bl[a].id || b.dim != bl[a].dim) fail("instance " + std::to_string(b.id) + " out of place");
    if (b.Sigma.rows() != b.dim || b.Sigma.cols() != b.dim) fail("Σ_ii of " + std::to_string(b.id) + " has wrong size");
    if (b.L.size() && (b.L.rows() != b.dim || b.L.cols() != b.dim)) fail("L of " + std::to_string(b.id));
    for (const FactorEntry& e : b.factors->entries()) {
      if (!has(e.partner)) fail(std::to_string(b.id) + " holds a factor for missing " + std::to_string(e.partner));
      const InstanceBelief& p = *inst_[static_cast<size_t>(index(e.partner))];
      const FactorEntry* back = p.factors->find(b.id);
      if (!back) fail("pair (" + std::to_string(b.id) + ", " + std::to_string(p.id) + ") on one side only");
      const int r = std::max(b.id, p.id) == b.id ? b.dim : p.dim;  // columns: the larger id's dim
      if (e.S_bar && (e.S_bar->rows() != b.dim || e.S_bar->cols() != r))
        fail("factor (" + std::to_string(b.id) + ", " + std::to_string(p.id) + ") has wrong size");
      if (!e.S_bar && b.id < p.id && b.dim != p.dim)
        fail("identity factor on the smaller id of (" + std::to_string(b.id) + ", " + std::to_string(p.id) + ")");
    }
  }
  const MatrixXd P = full();
  if (!P.allFinite()) fail("covariance not finite");
  if (!(P - P.transpose()).isZero(1e-9 * (1.0 + P.norm()))) fail("covariance not symmetric");
  if (mode_ == Mode::DP) {
    if (P.size() && Eigen::LLT<MatrixXd>(P).info() != Eigen::Success) fail("covariance not positive definite");
    return;
  }
  // DAH: the per-instance correction Σ_ik' = Σ_ii' Σ_ii⁻¹ Σ_ik keeps every Σ_ii and every pair
  // [Σ_ii Σ_ik; Σ_ki Σ_kk] positive definite (Schur complement Σ_kk − Σ_ki Σ_ii⁻¹ Σ_ii' Σ_ii⁻¹ Σ_ik
  // ≥ Σ_kk − Σ_ki Σ_ii⁻¹ Σ_ik), hence every stacked Σ_PP of a two-instance update, but not the whole
  // reconstructed matrix (docs/modular_estimator.md, "DAH and positive definiteness").
  for (size_t a = 0; a < bl.size(); ++a) {
    if (Eigen::LLT<MatrixXd>(inst_[a]->Sigma).info() != Eigen::Success)
      fail("Σ_ii of " + std::to_string(bl[a].id) + " not positive definite");
    for (const FactorEntry& e : inst_[a]->factors->entries()) {
      const int kb = index(e.partner);
      if (kb <= static_cast<int>(a)) continue;
      const StateBlock& b = bl[static_cast<size_t>(kb)];
      MatrixXd J(bl[a].dim + b.dim, bl[a].dim + b.dim);
      J.topLeftCorner(bl[a].dim, bl[a].dim) = P.block(bl[a].offset, bl[a].offset, bl[a].dim, bl[a].dim);
      J.topRightCorner(bl[a].dim, b.dim) = P.block(bl[a].offset, b.offset, bl[a].dim, b.dim);
      J.bottomLeftCorner(b.dim, bl[a].dim) = P.block(b.offset, bl[a].offset, b.dim, bl[a].dim);
      J.bottomRightCorner(b.dim, b.dim) = P.block(b.offset, b.offset, b.dim, b.dim);
      if (Eigen::LLT<MatrixXd>(J).info() != Eigen::Success)
        fail("pair (" + std::to_string(bl[a].id) + ", " + std::to_string(b.id) + ") not positive definite");
    }
  }
}

}  // namespace meshnav::estimator