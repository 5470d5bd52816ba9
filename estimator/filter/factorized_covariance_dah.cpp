/// @file factorized_covariance_dah.cpp
/// @brief FactorizedCovariance, second part: the DAH update, updateDah(), one path for every DAH
/// measurement (a range or baro scalar on two instances, a joint set's whole stack, a vector such
/// as a ZUPT): the class DahUpdate, compiled for stack storage (the common small stacks) and for
/// heap storage, with fixed-size kernels for the IMU (15) and anchors (3). The first part,
/// factorized_covariance.cpp, holds the instances, propagation, DP's update and write-back and the
/// invariant check.

#include "estimator/filter/factorized_covariance.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "estimator/core/imu_state.h"
#include "estimator/filter/dense_ekf_update.h"
#include "estimator/filter/factorized_covariance_internals.h"

namespace meshnav::estimator {

namespace {

using Eigen::MatrixXd;
using factorized_internal::InstMat;
using factorized_internal::kMaxInstanceDim;
using factorized_internal::roughCondition;
using factorized_internal::shared;
using M15 = Eigen::Matrix<double, ImuErr::kDim, ImuErr::kDim>;
using M15x3 = Eigen::Matrix<double, ImuErr::kDim, 3>;

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

/// The scalar DAH correction with the fixed-size kernel of the instance's size.
template <typename UV>
void foldScalarCorrection(InstanceBelief& b, const UV& u, double s) {
  if (b.dim == ImuErr::kDim)
    foldDahCorrection<ImuErr::kDim>(b, u, s);
  else if (b.dim == 3)
    foldDahCorrection<3>(b, u, s);
  else
    foldDahCorrection<Eigen::Dynamic>(b, u, s);
}

/// L_i⁻¹ into `out` with the kernel of the instance's size; false: re-normalize instead.
template <typename Out>
bool invertPendingFactor(const InstanceBelief& b, Out& out) {
  constexpr int kSteps = FactorizedCovariance::kMaxLazySteps;
  constexpr double kCond = FactorizedCovariance::kMaxLazyCondition;
  return b.dim == ImuErr::kDim ? invertPending<ImuErr::kDim>(b, kSteps, kCond, out)
         : b.dim == 3          ? invertPending<3>(b, kSteps, kCond, out)
                               : invertPending<Eigen::Dynamic>(b, kSteps, kCond, out);
}

/// True when every partner of `b` is among the sorted ids [first, last) (a closed participant: no
/// pair of it with an instance outside the update). O(min(#partners, #ids) log #ids).
bool partnersWithin(const InstanceBelief& b, const SensorId* first, const SensorId* last) {
  const auto& entries = b.factors->entries();
  if (entries.size() >= static_cast<size_t>(last - first)) return false;  // partners are other instances than b
  return std::all_of(entries.begin(), entries.end(),
                     [&](const FactorEntry& e) { return std::binary_search(first, last, e.partner); });
}

/// One participant of a DAH update.
struct Part {
  int k = 0, off = 0, dim = 0;  ///< index in the layout, offset and size in the stacked state
  SensorId id = 0;
};

}  // namespace

/// The DAH update (FactorizedCovariance::updateDah) on the stacked participants P: Σ_PP, the EKF
/// update (scalar: the rank-one form; vector: denseEkfUpdate), then the write-back: Σ_ii' per
/// participant; a closed participant (every partner in P) restarts with L_i = I; a private update
/// (|P| = 1) folds I − K H_i into L_i exactly; any other folds DAH's correction Σ_ii' Σ_ii⁻¹
/// (scalar: I − u wᵀ / s, w = Σ_ii⁻¹ u); then L_i'⁻¹ and the pair factors within P (smaller id
/// S̄_ij = L_i'⁻¹ Σ_ij', larger id S̄_ji = L_j'⁻¹). `MaxN` / `MaxParts`: stack storage for at most
/// that many stacked states / participants (Eigen::Dynamic: heap; also vector measurements).
template <int MaxN, int MaxParts>
class DahUpdate {
  static constexpr bool kFixed = MaxN != Eigen::Dynamic;
  using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, MaxN, MaxN>;
  using Vec = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, MaxN, 1>;
  using Factor = std::conditional_t<kFixed, InstMat, MatrixXd>;
  template <typename T>
  using PerPart = std::conditional_t<kFixed, std::array<T, static_cast<size_t>(MaxParts)>, std::vector<T>>;

 public:
  /// `ks`: the participants' layout indices, ascending and distinct (fit MaxN / MaxParts).
  DahUpdate(FactorizedCovariance& fc, const Linearization& lin, const int* ks, int np)
      : fc_(fc), lin_(lin), np_(np) {
    if constexpr (!kFixed) {
      pp_.resize(static_cast<size_t>(np));
      Linv_.resize(static_cast<size_t>(np));
      has_inv_.assign(static_cast<size_t>(np), false);
    }
    for (int a = 0; a < np_; ++a) {
      const StateBlock& b = fc_.layout_.blocks()[static_cast<size_t>(ks[a])];
      pp_[static_cast<size_t>(a)] = Part{ks[a], n_, b.dim, b.id};
      n_ += b.dim;
    }
  }

  /// Σ_PP: blocks Σ_ii and Σ_ij = S_ij S_jiᵀ (FactorizedCovariance::pairCovInto: identity
  /// factors, among them a partner's S̄ that is the L⁻¹ of its current L, are not multiplied).
  void stackCovariance() {
    P_.resize(n_, n_);
    for (int a = 0; a < np_; ++a) {
      const Part& pa = part(a);
      P_.block(pa.off, pa.off, pa.dim, pa.dim) = belief(pa).Sigma;
      for (int c = a + 1; c < np_; ++c) {
        const Part& pc = part(c);
        auto C = P_.block(pa.off, pc.off, pa.dim, pc.dim);
        fc_.pairCovInto(pa.k, pc.k, C);
        P_.block(pc.off, pa.off, pc.dim, pa.dim) = C.transpose();
      }
    }
  }

  /// The EKF update of Σ_PP. Scalar (the arithmetic of denseEkfUpdate with m = 1): u = Σ_PP hᵀ,
  /// s = h u + R, NIS = r² / s (gated), then s taken as Linearization::stepCovariance (R_eff),
  /// K = u / s, Joseph form P ← P − K uᵀ − u Kᵀ + K s Kᵀ (or P ← P − K uᵀ), symmetrized. Vector: denseEkfUpdate. Fills `res`; false when gated (or the NIS
  /// is not finite).
  bool ekfUpdate(double nis_gate, bool joseph, FactorizedCovariance::Result* res) {
    if constexpr (!kFixed) {
      if (!scalar()) return denseUpdate(nis_gate, joseph, res);
    }
    for (const JacobianBlock& jb : lin_.blocks)
      if (jb.H.rows() != 1 || jb.H.cols() != partOf(jb.id).dim)
        throw std::logic_error("EKF update: Jacobian block of " + std::to_string(jb.id) + " has wrong size");
    U_ = Vec::Zero(n_);
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
    if (!lin_.passesGate(res->nis, nis_gate)) return false;
    // Correlated errors, the Huber weight and the NLOS mixture's collapse (Linearization::scalarStep),
    // after the gate: δx = K r', P ← P − u uᵀ (s_step − c)/s_step².
    const Linearization::ScalarStep st = lin_.scalarStep(s_, res->nis);
    s_ = st.s_step;
    spread_ = st.spread_m2;
    Kv_.resize(n_);
    for (int i = 0; i < n_; ++i) Kv_(i) = invertible_ ? U_(i) / s_ : 0.0;
    // Element (i, j) and (j, i) in one pass over the upper triangle, then symmetrized.
    auto updated = [&](int i, int j) {
      return joseph ? P_(i, j) + ((-(Kv_(i) * U_(j)) - Kv_(j) * U_(i)) + (Kv_(i) * (s_ + spread_)) * Kv_(j))
                    : P_(i, j) - Kv_(i) * U_(j) + (Kv_(i) * spread_) * Kv_(j);
    };
    for (int j = 0; j < n_; ++j) {
      for (int i = 0; i < j; ++i) P_(i, j) = P_(j, i) = 0.5 * (updated(i, j) + updated(j, i));
      P_(j, j) = updated(j, j);
    }
    res->dx.resize(n_);
    for (int i = 0; i < n_; ++i) res->dx(i) = Kv_(i) * st.residual;
    // From here Kv_ is the gain of the covariance, K (s − c)/s (the write-back's factors).
    if (spread_ > 0.0) Kv_ *= covGainScale();
    accept(res);
    return true;
  }

  /// The DAH write-back of an accepted update.
  void writeBack(Timestamp t) {
    if (np_ == 0) return;
    if (np_ == 1) {
      writeBackPrivate(t);
      return;
    }
    foldJointCorrections(t);
    invertPendingFactors();
    setPairFactors();
  }

 private:
  const Part& part(int a) const { return pp_[static_cast<size_t>(a)]; }
  const InstanceBelief& belief(const Part& p) const { return *fc_.inst_[static_cast<size_t>(p.k)]; }
  const Part& partOf(SensorId id) const {
    for (int a = 0; a < np_; ++a)
      if (part(a).id == id) return part(a);
    throw std::logic_error("FactorizedCovariance::update: Jacobian block of " + std::to_string(id) +
                           " names no participant");
  }
  bool scalar() const { return lin_.dim() == 1 && lin_.R.rows() == 1 && lin_.R.cols() == 1; }

  void accept(FactorizedCovariance::Result* res) const {
    res->accepted = true;
    res->blocks.resize(static_cast<size_t>(np_));
    for (int a = 0; a < np_; ++a) {
      const Part& p = part(a);
      res->blocks[static_cast<size_t>(a)] =
          StateBlock{p.id, fc_.layout_.blocks()[static_cast<size_t>(p.k)].kind, p.off, p.dim};
    }
  }

  /// Vector measurement: denseEkfUpdate on the stacked Σ_PP (heap storage only).
  bool denseUpdate(double nis_gate, bool joseph, FactorizedCovariance::Result* res) {
    StateLayout sub;
    for (int a = 0; a < np_; ++a) sub.add(part(a).id, fc_.layout_.blocks()[static_cast<size_t>(part(a).k)].kind, part(a).dim);
    DenseUpdateOutput out = denseEkfUpdate(P_, sub, lin_, nis_gate, joseph);
    res->nis = out.nis;
    if (!out.accepted) return false;
    res->dx = std::move(out.dx);
    K_ = std::move(out.K);
    accept(res);
    return true;
  }

  /// Private update: Σ_ik' = (I − K h_i) Σ_ik exactly: L_i ← (I − K H_i) L_i.
  void writeBackPrivate(Timestamp t) {
    const Part& p = part(0);
    const JacobianBlock& jb = *lin_.find(p.id);
    InstanceBelief& b = fc_.mut(p.k);
    b.L_inv.reset();
    if (!scalar()) {
      const MatrixXd M = MatrixXd::Identity(p.dim, p.dim) - K_ * jb.H;
      b.L = b.L.size() ? MatrixXd(M * b.L) : M;
    } else if (!b.L.size()) {
      b.L.resize(p.dim, p.dim);
      for (int j = 0; j < p.dim; ++j)
        for (int i = 0; i < p.dim; ++i) b.L(i, j) = (i == j ? 1.0 : 0.0) - Kv_(i) * jb.H(0, j);
    } else if (p.dim == ImuErr::kDim) {
      Eigen::Map<M15> L(b.L.data());
      const Eigen::Matrix<double, 1, ImuErr::kDim> hL =
          Eigen::Map<const Eigen::Matrix<double, 1, ImuErr::kDim>>(jb.H.data()) * L;
      L.noalias() -= Eigen::Map<const Eigen::Matrix<double, ImuErr::kDim, 1>>(Kv_.data()) * hL;
    } else {
      const Eigen::RowVectorXd hL = jb.H * b.L;
      b.L.noalias() -= Kv_.head(p.dim) * hL;
    }
    b.Sigma = P_;
    b.t = t;
    if (++b.lazy_steps > FactorizedCovariance::kMaxLazySteps) fc_.renormalize(p.id);
  }

  /// 1. Σ_ii' and the pending factors: closed participants restart (L_i = I), the others fold
  /// DAH's correction of their pairs with instances outside P.
  void foldJointCorrections(Timestamp t) {
    PerPart<SensorId> ids{};  // the participants' ids, sorted
    if constexpr (!kFixed) ids.resize(static_cast<size_t>(np_));
    for (int a = 0; a < np_; ++a) ids[static_cast<size_t>(a)] = part(a).id;
    std::sort(ids.begin(), ids.begin() + np_);
    for (int a = 0; a < np_; ++a) {
      const Part& p = part(a);
      InstanceBelief& b = fc_.mut(p.k);
      const auto Sigma_new = P_.block(p.off, p.off, p.dim, p.dim);
      b.L_inv.reset();  // L_i changes (step 2 sets the new one)
      if (partnersWithin(b, ids.data(), ids.data() + np_)) {
        // Every correlation of i is a pair within P, written exactly in step 3: no pair is left
        // for the DAH correction, so L_i restarts as the identity (a DP write-back for i).
        b.L.resize(0, 0);
        b.lazy_steps = 0;
      } else {
        if (!scalar()) {
          // Σ_ik' ≈ Σ_ii' Σ_ii⁻¹ Σ_ik = (Σ_ii⁻¹ Σ_ii')ᵀ Σ_ik.
          const MatrixXd M = b.Sigma.ldlt().solve(MatrixXd(Sigma_new)).transpose();
          b.L = b.L.size() ? MatrixXd(M * b.L) : M;
        } else if (invertible_) {  // else K = 0: nothing changed
          // Σ_ii' = Σ_ii − u uᵀ (s − c)/s²: the fold's s is s²/(s − c) (infinite: Σ_ii unchanged).
          const double g = covGainScale();
          foldScalarCorrection(b, U_.segment(p.off, p.dim), g != 0.0 ? s_ / g : std::numeric_limits<double>::infinity());
        }
        ++b.lazy_steps;
      }
      b.Sigma = Sigma_new;
      b.t = t;
    }
  }

  /// 2. L_i'⁻¹ of the participants (re-normalize when L_i' is badly conditioned or old).
  void invertPendingFactors() {
    for (int a = 0; a < np_; ++a) {
      const Part& p = part(a);
      const InstanceBelief& b = belief(p);
      if (b.L.size() == 0) continue;
      if (invertPendingFactor(b, Linv_[static_cast<size_t>(a)]))
        has_inv_[static_cast<size_t>(a)] = true;
      else
        fc_.renormalize(p.id);
    }
  }

  /// 3. Pair factors within P: smaller id S̄_ij = L_i'⁻¹ Σ_ij' (written into its previous storage
  /// when no snapshot shares it), larger id S̄_ji = L_j'⁻¹ (one shared matrix per participant).
  void setPairFactors() {
    PerPart<std::shared_ptr<const MatrixXd>> inv_shared{};
    if constexpr (!kFixed) inv_shared.resize(static_cast<size_t>(np_));
    SensorId smallest = part(0).id;
    for (int a = 1; a < np_; ++a) smallest = std::min(smallest, part(a).id);
    for (int a = 0; a < np_; ++a) {
      // The smallest id is the larger one of no pair: its L⁻¹ is not stored.
      if (!has_inv_[static_cast<size_t>(a)] || part(a).id == smallest) continue;
      inv_shared[static_cast<size_t>(a)] = shared(MatrixXd(Linv_[static_cast<size_t>(a)]));
      fc_.mut(part(a).k).L_inv = inv_shared[static_cast<size_t>(a)];
    }
    for (int a = 0; a < np_; ++a) {
      for (int c = a + 1; c < np_; ++c) {
        const bool a_small = part(a).id < part(c).id;
        const size_t si = static_cast<size_t>(a_small ? a : c), li = static_cast<size_t>(a_small ? c : a);
        const Part &ps = pp_[si], &pl = pp_[li];
        const auto C = P_.block(ps.off, pl.off, ps.dim, pl.dim);
        FactorEntry& e = FactorizedCovariance::mutDict(fc_.mut(ps.k)).slot(pl.id);
        MatrixXd& S_bar = factorized_internal::writableFactor(e.S_bar, ps.dim, pl.dim);
        if (!has_inv_[si])
          S_bar = C;
        else if (ps.dim == ImuErr::kDim && pl.dim == 3)
          Eigen::Map<M15x3>(S_bar.data()).noalias() = Eigen::Map<const M15>(Linv_[si].data()).lazyProduct(M15x3(C));
        else if (ps.dim == 3 && pl.dim == 3)
          Eigen::Map<Eigen::Matrix3d>(S_bar.data()).noalias() =
              Eigen::Map<const Eigen::Matrix3d>(Linv_[si].data()).lazyProduct(Eigen::Matrix3d(C));
        else
          S_bar.noalias() = Linv_[si] * C;
        FactorizedCovariance::mutDict(fc_.mut(pl.k)).set(ps.id, inv_shared[li]);
      }
    }
  }

  FactorizedCovariance& fc_;
  const Linearization& lin_;
  PerPart<Part> pp_{};
  int np_ = 0;  ///< participants
  int n_ = 0;   ///< stacked dimension
  Mat P_;       ///< Σ_PP, updated in place
  Vec U_, Kv_;  ///< scalar update: Σ_PP hᵀ and the gain
  double s_ = 0.0;
  /// The NLOS collapse's spread c of a scalar update (0 without it): Σ' = Σ − u uᵀ (s − c)/s², so
  /// the factors' gain is K (s − c)/s (covGainScale).
  double spread_ = 0.0;
  double covGainScale() const { return spread_ > 0.0 ? (s_ - spread_) / s_ : 1.0; }
  bool invertible_ = false;
  MatrixXd K_;  ///< vector update: gain
  PerPart<Factor> Linv_{};
  PerPart<bool> has_inv_{};
};

namespace {

/// Runs the steps of one DAH update with the storage `U`.
template <typename U>
FactorizedCovariance::Result runDahUpdate(FactorizedCovariance& fc, const Linearization& lin, const int* ks, int np,
                                          double nis_gate, bool joseph, Timestamp t) {
  FactorizedCovariance::Result res;
  U u(fc, lin, ks, np);
  u.stackCovariance();
  if (u.ekfUpdate(nis_gate, joseph, &res)) u.writeBack(t);
  return res;
}

}  // namespace

FactorizedCovariance::Result FactorizedCovariance::updateDah(const Linearization& lin, double nis_gate, Timestamp t) {
  // Participants P in layout order: the named instances (no heap for ≤ 4 without joint sets) and
  // their joint sets' members.
  constexpr size_t kNamedInline = 4;
  std::array<int, kNamedInline> named{};
  std::vector<int> many;
  const int* ks = named.data();
  int np = 0;
  if (lin.blocks.size() <= kNamedInline && !namesJointSet(lin)) {
    for (const JacobianBlock& jb : lin.blocks) {
      if (!has(jb.id)) throw std::logic_error("FactorizedCovariance::update: no instance " + std::to_string(jb.id));
      named[static_cast<size_t>(np++)] = index(jb.id);
    }
    std::sort(named.begin(), named.begin() + np);
    np = static_cast<int>(std::unique(named.begin(), named.begin() + np) - named.begin());
  } else {
    many = dahParticipants(lin);
    ks = many.data();
    np = static_cast<int>(many.size());
  }
  int n = 0, largest = 0;
  for (int a = 0; a < np; ++a) {
    const int d = layout_.blocks()[static_cast<size_t>(ks[a])].dim;
    n += d;
    largest = std::max(largest, d);
  }
  // Stack storage when everything fits (every range and baro update; a joint set of the IMU and
  // up to ≈ 15 anchors), heap otherwise and for vector measurements.
  const bool scalar = lin.dim() == 1 && lin.R.rows() == 1 && lin.R.cols() == 1;
  if (scalar && largest <= kMaxInstanceDim && n <= 32 && np <= 8)
    return runDahUpdate<DahUpdate<32, 8>>(*this, lin, ks, np, nis_gate, joseph_, t);
  if (scalar && largest <= kMaxInstanceDim && n <= 64 && np <= 20)
    return runDahUpdate<DahUpdate<64, 20>>(*this, lin, ks, np, nis_gate, joseph_, t);
  return runDahUpdate<DahUpdate<Eigen::Dynamic, Eigen::Dynamic>>(*this, lin, ks, np, nis_gate, joseph_, t);
}

}  // namespace meshnav::estimator
