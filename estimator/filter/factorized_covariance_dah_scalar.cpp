/// @file factorized_covariance_dah_scalar.cpp
/// @brief FactorizedCovariance, second part: the DAH fast path for a scalar update (UWB range,
/// baro), updateDahScalar(), with its stack-storage types and fixed-size kernels. The first part,
/// factorized_covariance.cpp, holds the instances, propagation, the general update and the
/// write-backs (DP and DAH) and the invariant check.

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

// ---- DAH scalar fast path (updateDahScalar): stack storage, fixed-size kernels per instance. ----
constexpr int kMaxParticipants = 4;
using factorized_internal::kMaxInstanceDim;
constexpr int kMaxStackedDim = 32;
/// The stacked Σ_PP and vectors over it without heap allocation.
using StackMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxStackedDim, kMaxStackedDim>;
using StackVec = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxStackedDim, 1>;
using factorized_internal::InstMat;

/// A⁻¹ of a fixed-size square matrix by Gauss elimination with partial pivoting on [A | I] (the
/// pivots and the elimination of Eigen's unblocked PartialPivLU; whole contiguous rows of row-major
/// storage, so every step is a fixed-size vector operation), then back substitution. Allocation-free;
/// a singular A gives non-finite entries (as Eigen's inverse does), which the caller checks.
template <int D>
Eigen::Matrix<double, D, D> luInverse(const Eigen::Matrix<double, D, D>& A) {
  // Rows padded to an even length (zero columns stay zero): aligned packets, no scalar tail.
  constexpr int kCols = D + D % 2;
  using RowMat = Eigen::Matrix<double, D, kCols, Eigen::RowMajor>;
  RowMat U = RowMat::Zero();
  U.template leftCols<D>() = A;
  RowMat X = RowMat::Identity();
  for (int k = 0; k < D; ++k) {
    int piv = k;
    double biggest = std::abs(U(k, k));
    for (int i = k + 1; i < D; ++i)
      if (std::abs(U(i, k)) > biggest) biggest = std::abs(U(i, k)), piv = i;
    if (biggest == 0.0) continue;  // singular: U(k, k) = 0 makes the result non-finite
    if (piv != k) {
      U.row(k).swap(U.row(piv));
      X.row(k).swap(X.row(piv));
    }
    // Rows i > k: the columns < k are zero in rows i and k; column k is not read again.
    for (int i = k + 1; i < D; ++i) {
      const double l = U(i, k) / U(k, k);
      U.row(i) -= l * U.row(k);
      X.row(i) -= l * X.row(k);
    }
  }
  for (int k = D - 1; k >= 0; --k) {
    X.row(k) *= 1.0 / U(k, k);
    for (int i = 0; i < k; ++i) X.row(i) -= U(i, k) * X.row(k);
  }
  return X.template leftCols<D>();
}

/// w = Σ⁻¹ u for a symmetric positive definite Σ of fixed size by Cholesky (Σ = C Cᵀ); false when
/// Σ is not numerically positive definite (the caller then uses Eigen's LDLT).
template <int D, typename UV>
bool choleskySolve(const Eigen::Map<const Eigen::Matrix<double, D, D>>& S, const UV& u, Eigen::Matrix<double, D, 1>* w) {
  Eigen::Matrix<double, D, D> C;  // lower triangle used
  for (int j = 0; j < D; ++j) {
    double d = S(j, j);
    for (int k = 0; k < j; ++k) d -= C(j, k) * C(j, k);
    if (!(d > 0.0)) return false;
    const double cjj = std::sqrt(d);
    C(j, j) = cjj;
    for (int i = j + 1; i < D; ++i) {
      double v = S(i, j);
      for (int k = 0; k < j; ++k) v -= C(i, k) * C(j, k);
      C(i, j) = v / cjj;
    }
  }
  Eigen::Matrix<double, D, 1>& x = *w;
  for (int i = 0; i < D; ++i) {  // C y = u
    double v = u(i);
    for (int k = 0; k < i; ++k) v -= C(i, k) * x(k);
    x(i) = v / C(i, i);
  }
  for (int i = D - 1; i >= 0; --i) {  // Cᵀ x = y
    double v = x(i);
    for (int k = i + 1; k < D; ++k) v -= C(k, i) * x(k);
    x(i) = v / C(i, i);
  }
  return true;
}

/// DAH correction of a participant i of a joint scalar update: L_i ← (Σ_ii' Σ_ii⁻¹) L_i. With
/// u = the participant's rows of Σ_PP hᵀ, s = h Σ_PP hᵀ + R and the optimal gain,
/// Σ_ii' = Σ_ii − u uᵀ / s, so Σ_ii' Σ_ii⁻¹ = I − u wᵀ / s with w = Σ_ii⁻¹ u and
/// L_i' = L_i − u (wᵀ L_i) / s: one solve and O(dim²), instead of dim right-hand sides of
/// Σ_ii Mᵀ = Σ_ii' and a dim³ product (the same matrix up to rounding).
template <int D, typename UV>
void foldDahCorrection(InstanceBelief& b, const UV& u, double s) {
  using Mat = Eigen::Matrix<double, D, D>;
  using Vec = Eigen::Matrix<double, D, 1>;
  const int d = b.dim;
  const Eigen::Map<const Mat> S_old(b.Sigma.data(), d, d);
  Vec w(d);
  if constexpr (D == Eigen::Dynamic) {
    w = S_old.ldlt().solve(u);
  } else {
    if (!choleskySolve<D>(S_old, u, &w)) w = S_old.ldlt().solve(u);
  }
  if (!b.L.size()) {
    b.L.resize(d, d);
    for (int j = 0; j < d; ++j)
      for (int i = 0; i < d; ++i) b.L(i, j) = (i == j ? 1.0 : 0.0) - u(i) * (w(j) / s);
    return;
  }
  Eigen::Map<Mat> L(b.L.data(), d, d);
  const Eigen::Matrix<double, 1, D> v = (w.transpose() * L) / s;
  for (int j = 0; j < d; ++j)
    for (int i = 0; i < d; ++i) L(i, j) -= u(i) * v(j);
}

/// L_i⁻¹ into `out`; false when L_i must be re-normalized instead (old, not finite, badly conditioned).
template <int D, typename Out>
bool invertPending(const InstanceBelief& b, int max_lazy_steps, double max_condition, Out& out) {
  using Mat = Eigen::Matrix<double, D, D>;
  const Eigen::Map<const Mat> L(b.L.data(), b.dim, b.dim);
  Mat inv;
  if constexpr (D == Eigen::Dynamic)
    inv = L.partialPivLu().inverse();
  else
    inv = luInverse<D>(L);
  if (b.lazy_steps > max_lazy_steps || !inv.allFinite() || roughCondition(L, inv) > max_condition) return false;
  out = inv;
  return true;
}

}  // namespace

namespace factorized_internal {

void foldScalarCorrection(InstanceBelief& b, const Eigen::Ref<const Eigen::VectorXd>& u, double s) {
  if (b.dim == ImuErr::kDim)
    foldDahCorrection<ImuErr::kDim>(b, u, s);
  else if (b.dim == 3)
    foldDahCorrection<3>(b, u, s);
  else
    foldDahCorrection<Eigen::Dynamic>(b, u, s);
}

template <typename Out>
bool invertPendingFactor(const InstanceBelief& b, Out& out) {
  constexpr int kSteps = FactorizedCovariance::kMaxLazySteps;
  constexpr double kCond = FactorizedCovariance::kMaxLazyCondition;
  return b.dim == ImuErr::kDim ? invertPending<ImuErr::kDim>(b, kSteps, kCond, out)
         : b.dim == 3          ? invertPending<3>(b, kSteps, kCond, out)
                               : invertPending<Eigen::Dynamic>(b, kSteps, kCond, out);
}
template bool invertPendingFactor(const InstanceBelief&, Eigen::MatrixXd&);

}  // namespace factorized_internal

/// The steps of updateDahScalar on its stack storage: the participants, Σ_PP, the scalar EKF
/// update, then the DAH write-back (private: one participant; joint: the rank-one correction of
/// each L_i, their inverses and the new pair factors).
class DahScalarUpdate {
 public:
  DahScalarUpdate(FactorizedCovariance& fc, const Linearization& lin) : fc_(fc), lin_(lin) {}

  /// Participants P in layout order with their offsets in the stacked state; false when the
  /// measurement is not for the fast path (not scalar, too many or too large participants).
  bool selectParticipants() {
    if (lin_.dim() != 1 || lin_.R.rows() != 1 || lin_.R.cols() != 1 || lin_.blocks.empty() ||
        lin_.blocks.size() > static_cast<size_t>(kMaxParticipants))
      return false;
    std::array<int, kMaxParticipants> ks{};
    int np = 0;
    for (const JacobianBlock& jb : lin_.blocks) {
      if (!fc_.has(jb.id)) throw std::logic_error("FactorizedCovariance::update: no instance " + std::to_string(jb.id));
      ks[static_cast<size_t>(np++)] = fc_.index(jb.id);
    }
    std::sort(ks.begin(), ks.begin() + np);
    np_ = static_cast<int>(std::unique(ks.begin(), ks.begin() + np) - ks.begin());
    n_ = 0;
    for (int a = 0; a < np_; ++a) {
      const StateBlock& b = fc_.layout_.blocks()[static_cast<size_t>(ks[static_cast<size_t>(a)])];
      if (b.dim > kMaxInstanceDim) return false;
      pp_[static_cast<size_t>(a)] = Part{ks[static_cast<size_t>(a)], n_, b.dim, b.id};
      n_ += b.dim;
    }
    if (n_ > kMaxStackedDim) return false;
    for (const JacobianBlock& jb : lin_.blocks)
      if (jb.H.rows() != 1 || jb.H.cols() != partOf(jb.id).dim)
        throw std::logic_error("EKF update: Jacobian block of " + std::to_string(jb.id) + " has wrong size");
    return true;
  }

  /// Stacks Σ_PP: blocks Σ_ii and Σ_ij = S_ij S_jiᵀ (identity factors are not multiplied).
  void stackCovariance() {
    P_.resize(n_, n_);
    for (int a = 0; a < np_; ++a) {
      const Part& pa = pp_[static_cast<size_t>(a)];
      P_.block(pa.off, pa.off, pa.dim, pa.dim) = fc_.inst_[static_cast<size_t>(pa.k)]->Sigma;
      for (int c = a + 1; c < np_; ++c) {
        const Part& pc = pp_[static_cast<size_t>(c)];
        auto C = P_.block(pa.off, pc.off, pa.dim, pc.dim);
        fc_.pairCovInto(pa.k, pc.k, C);  // instances ≤ kMaxInstanceDim: stack storage, as before
        P_.block(pc.off, pa.off, pc.dim, pa.dim) = C.transpose();
      }
    }
  }

  /// Scalar EKF update (the arithmetic of denseEkfUpdate with m = 1): u = Σ_PP hᵀ, s = h u + R,
  /// NIS = r² / s, K = u / s, Joseph form P ← P − K uᵀ − u Kᵀ + K s Kᵀ (or P ← P − K uᵀ),
  /// symmetrized. Fills `res`; false when the measurement is gated (or its NIS is not finite).
  bool ekfUpdate(double nis_gate, bool joseph, FactorizedCovariance::Result* res) {
    U_ = StackVec::Zero(n_);
    for (const JacobianBlock& jb : lin_.blocks) {
      const Part& p = partOf(jb.id);
      U_.noalias() += P_.middleCols(p.off, p.dim) * jb.H.transpose();
    }
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 1, 1> S = lin_.R;
    for (const JacobianBlock& jb : lin_.blocks) {
      const Part& p = partOf(jb.id);
      S.noalias() += jb.H * U_.middleRows(p.off, p.dim);
    }
    s_ = S(0, 0);
    invertible_ = std::abs(s_) > std::numeric_limits<double>::min();  // LDLT's pseudo-inverse
    const double r = lin_.residual(0);
    res->nis = r * (invertible_ ? r / s_ : 0.0);
    if (!std::isfinite(res->nis) || (nis_gate > 0.0 && res->nis > nis_gate)) return false;
    K_.resize(n_);
    for (int i = 0; i < n_; ++i) K_(i) = invertible_ ? U_(i) / s_ : 0.0;
    if (joseph) {
      for (int j = 0; j < n_; ++j)
        for (int i = 0; i < n_; ++i)
          P_(i, j) = P_(i, j) + ((-(K_(i) * U_(j)) - K_(j) * U_(i)) + (K_(i) * s_) * K_(j));
    } else {
      for (int j = 0; j < n_; ++j)
        for (int i = 0; i < n_; ++i) P_(i, j) -= K_(i) * U_(j);
    }
    for (int j = 0; j < n_; ++j)
      for (int i = j + 1; i < n_; ++i) P_(i, j) = P_(j, i) = 0.5 * (P_(i, j) + P_(j, i));
    res->accepted = true;
    res->dx.resize(n_);
    for (int i = 0; i < n_; ++i) res->dx(i) = K_(i) * r;
    res->blocks.resize(static_cast<size_t>(np_));
    for (int a = 0; a < np_; ++a) {
      const Part& p = pp_[static_cast<size_t>(a)];
      res->blocks[static_cast<size_t>(a)] =
          StateBlock{p.id, fc_.layout_.blocks()[static_cast<size_t>(p.k)].kind, p.off, p.dim};
    }
    return true;
  }

  /// The DAH write-back of an accepted update.
  void writeBack(Timestamp t) {
    if (np_ == 1) {
      writeBackPrivate(t);
      return;
    }
    foldJointCorrections(t);
    invertPendingFactors();
    setPairFactors();
  }

 private:
  struct Part {
    int k = 0, off = 0, dim = 0;
    SensorId id = 0;
  };
  const Part& partOf(SensorId id) const {
    for (int a = 0; a < np_; ++a)
      if (pp_[static_cast<size_t>(a)].id == id) return pp_[static_cast<size_t>(a)];
    throw std::logic_error("DahScalarUpdate: no participant " + std::to_string(id));
  }

  /// Private update: Σ_ik' = (I − K h_i) Σ_ik exactly: L_i ← (I − K h_i) L_i = L_i − K (h_i L_i).
  void writeBackPrivate(Timestamp t) {
    const Part& p = pp_[0];
    const JacobianBlock& jb = *lin_.find(p.id);
    InstanceBelief& b = fc_.mut(p.k);
    if (!b.L.size()) {
      b.L.resize(p.dim, p.dim);
      for (int j = 0; j < p.dim; ++j)
        for (int i = 0; i < p.dim; ++i) b.L(i, j) = (i == j ? 1.0 : 0.0) - K_(i) * jb.H(0, j);
    } else if (p.dim == ImuErr::kDim) {
      using M15 = Eigen::Matrix<double, ImuErr::kDim, ImuErr::kDim>;
      Eigen::Map<M15> L(b.L.data());
      const Eigen::Matrix<double, 1, ImuErr::kDim> hL =
          Eigen::Map<const Eigen::Matrix<double, 1, ImuErr::kDim>>(jb.H.data()) * L;
      L.noalias() -= Eigen::Map<const Eigen::Matrix<double, ImuErr::kDim, 1>>(K_.data()) * hL;
    } else {
      const Eigen::RowVectorXd hL = jb.H * b.L;
      b.L.noalias() -= K_.head(p.dim) * hL;
    }
    b.Sigma = P_;
    b.t = t;
    if (++b.lazy_steps > FactorizedCovariance::kMaxLazySteps) fc_.renormalize(p.id);
  }

  /// 1. Σ_ii' and the pending factors of a joint update (foldDahCorrection).
  void foldJointCorrections(Timestamp t) {
    for (int a = 0; a < np_; ++a) {
      const Part& p = pp_[static_cast<size_t>(a)];
      InstanceBelief& b = fc_.mut(p.k);
      if (invertible_) {  // else K = 0: nothing changed
        factorized_internal::foldScalarCorrection(b, U_.segment(p.off, p.dim), s_);
      }
      b.Sigma = P_.block(p.off, p.off, p.dim, p.dim);
      b.t = t;
      ++b.lazy_steps;
    }
  }

  /// 2. L_i'⁻¹ of the participants (re-normalize when L_i' is badly conditioned or old).
  void invertPendingFactors() {
    for (int a = 0; a < np_; ++a) {
      const Part& p = pp_[static_cast<size_t>(a)];
      const InstanceBelief& b = *fc_.inst_[static_cast<size_t>(p.k)];
      if (b.L.size() == 0) continue;
      if (factorized_internal::invertPendingFactor(b, Linv_[static_cast<size_t>(a)]))
        has_inv_[static_cast<size_t>(a)] = true;
      else
        fc_.renormalize(p.id);
    }
  }

  /// 3. Pair factors within P: smaller id S̄_ij = L_i'⁻¹ Σ_ij', larger id S̄_ji = L_j'⁻¹ (S_ji = I).
  void setPairFactors() {
    for (int a = 0; a < np_; ++a) {
      for (int c = a + 1; c < np_; ++c) {
        const bool a_small = pp_[static_cast<size_t>(a)].id < pp_[static_cast<size_t>(c)].id;
        const size_t si = static_cast<size_t>(a_small ? a : c), li = static_cast<size_t>(a_small ? c : a);
        const Part &ps = pp_[si], &pl = pp_[li];
        const auto C = P_.block(ps.off, pl.off, ps.dim, pl.dim);
        MatrixXd S_bar(ps.dim, pl.dim);
        if (!has_inv_[si]) {
          S_bar = C;
        } else if (ps.dim == ImuErr::kDim && pl.dim == 3) {
          using M15 = Eigen::Matrix<double, ImuErr::kDim, ImuErr::kDim>;
          using M15x3 = Eigen::Matrix<double, ImuErr::kDim, 3>;
          Eigen::Map<M15x3>(S_bar.data()).noalias() = Eigen::Map<const M15>(Linv_[si].data()).lazyProduct(M15x3(C));
        } else {
          S_bar.noalias() = Linv_[si] * C;
        }
        FactorizedCovariance::mutDict(fc_.mut(ps.k)).set(pl.id, shared(std::move(S_bar)));
        FactorizedCovariance::mutDict(fc_.mut(pl.k)).set(ps.id, has_inv_[li] ? shared(MatrixXd(Linv_[li])) : nullptr);
      }
    }
  }

  FactorizedCovariance& fc_;
  const Linearization& lin_;
  std::array<Part, kMaxParticipants> pp_;
  int np_ = 0;  ///< participants
  int n_ = 0;   ///< stacked dimension
  StackMat P_;  ///< Σ_PP, updated in place
  StackVec U_, K_;
  double s_ = 0.0;
  bool invertible_ = false;
  std::array<InstMat, kMaxParticipants> Linv_;
  std::array<bool, kMaxParticipants> has_inv_{};
};

bool FactorizedCovariance::updateDahScalar(const Linearization& lin, double nis_gate, Timestamp t, Result* res) {
  DahScalarUpdate u(*this, lin);
  if (!u.selectParticipants()) return false;
  u.stackCovariance();
  if (u.ekfUpdate(nis_gate, joseph_, res)) u.writeBack(t);
  return true;
}

}  // namespace meshnav::estimator
