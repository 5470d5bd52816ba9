#include "estimator/filter/centralized_ekf.h"

#include "estimator/filter/dense_ekf_update.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <stdexcept>

namespace meshnav::estimator {

namespace {

/// The IMU transition Φ by its nonzero entries (ImuPropagator: 87 of the 225, 15 of them ones):
/// L Φᵀ for an n × 15 L is, column by column, out.col(i) = Σ_{Φ(i,j) ≠ 0} Φ(i,j) L.col(j): long
/// contiguous columns, no packing, no product of a zero, no multiplication by a one. The entries
/// are read from Φ, so any Φ is exact.
class SparseImuTransition {
 public:
  explicit SparseImuTransition(const ImuMatrix& Phi) {
    for (int i = 0; i < kI; ++i) {
      first_[i] = n_;
      for (int j = 0; j < kI; ++j)
        if (Phi(i, j) != 0.0) entries_[n_++] = Entry{j, Phi(i, j)};
    }
    first_[kI] = n_;
  }
  /// out = L Φᵀ for a 15-column L (out must not alias L).
  template <typename Derived, typename Out>
  void timesTransposed(const Eigen::MatrixBase<Derived>& L, Out& out) const {
    out.resize(L.rows(), kI);
    for (int i = 0; i < kI; ++i) {
      auto o = out.col(i);
      if (first_[i] == first_[i + 1]) {
        o.setZero();
        continue;
      }
      for (int k = first_[i]; k < first_[i + 1]; ++k) {
        const Entry& e = entries_[k];
        const bool first = k == first_[i];
        if (e.value == 1.0) {
          if (first)
            o = L.col(e.col);
          else
            o += L.col(e.col);
        } else if (first) {
          o = e.value * L.col(e.col);
        } else {
          o += e.value * L.col(e.col);
        }
      }
    }
  }

 private:
  static constexpr int kI = ImuErr::kDim;
  struct Entry {
    int col = 0;
    double value = 0.0;
  };
  Entry entries_[kI * kI];  ///< the nonzero entries by row
  int first_[kI + 1] = {};
  int n_ = 0;
};

}  // namespace

CentralizedEkf::CentralizedEkf(const ImuPropagator& propagator, const KindRandomWalks& random_walks, bool joseph_form)
    : propagator_(propagator), random_walks_(random_walks), joseph_form_(joseph_form) {}

void CentralizedEkf::reset(SensorId imu_id, const ImuState& x, const ImuMatrix& cov, Timestamp t) {
  x_ = NominalState{};
  x_.t = t;
  x_.imu_id = imu_id;
  x_.imu = x;
  layout_ = StateLayout{};
  P_.resize(0, 0);
  appendBlock(imu_id, kindOf<ImuKind>, cov);
}

void CentralizedEkf::appendBlock(SensorId id, InstanceKind kind, const Eigen::MatrixXd& cov) {
  const int n = layout_.dim();
  const StateBlock& b = layout_.add(id, kind, static_cast<int>(cov.rows()));
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(layout_.dim(), layout_.dim());
  P.topLeftCorner(n, n) = P_;
  P.block(b.offset, b.offset, b.dim, b.dim) = 0.5 * (cov + cov.transpose());
  P_ = std::move(P);
}

bool CentralizedEkf::removeInstance(SensorId id) {
  const StateBlock* blk = layout_.find(id);
  if (!blk || blk->kind == kindOf<ImuKind>) return false;
  const int off = blk->offset, d = blk->dim, n = layout_.dim(), tail = n - off - d;
  Eigen::MatrixXd P(n - d, n - d);
  P.topLeftCorner(off, off) = P_.topLeftCorner(off, off);
  P.topRightCorner(off, tail) = P_.topRightCorner(off, tail);
  P.bottomLeftCorner(tail, off) = P_.bottomLeftCorner(tail, off);
  P.bottomRightCorner(tail, tail) = P_.bottomRightCorner(tail, tail);
  P_ = std::move(P);
  layout_.remove(id);
  x_.erase(id);
  return true;
}

void CentralizedEkf::propagate(const Eigen::Vector3d& acc_m_s2, const Eigen::Vector3d& gyro_rad_s, Timestamp t_to) {
  const double dt = (t_to - x_.t).sec();
  if (dt <= 0.0) return;
  ImuMatrix Phi, Q;
  propagator_.propagate(x_.imu, acc_m_s2, gyro_rad_s, dt, &Phi, &Q);
  noteTransition(Phi);
  x_.t = t_to;
  constexpr int kI = ImuErr::kDim;  // the IMU block is always first
  const int n = layout_.dim();
  // P ← Φ_full P Φ_fullᵀ with Φ_full = diag(Φ, I): the IMU columns P Φ_fullᵀ (their blocks
  // P_jI Φᵀ, j ≠ I, are final; the IMU rows take their transpose), then the IMU block
  // Φ (P_II Φᵀ) + Q. (Before, two dense products over all n rows and columns, of which the mirror
  // overwrote the second's rows below the IMU block: 15 × 15 × n multiplications a step for nothing.)
  const SparseImuTransition phi(Phi);
  auto& cols = scratch_.cols;
  phi.timesTransposed(P_.leftCols<kI>(), cols);
  ImuMatrix Pii;  // Φ P_II Φᵀ = (P_II Φᵀ)ᵀ Φᵀ, P_II symmetric
  phi.timesTransposed(cols.topRows<kI>().transpose(), Pii);
  Pii += Q;
  // Keep the touched rows/columns exactly symmetric.
  P_.topLeftCorner<kI, kI>() = 0.5 * (Pii + Pii.transpose());
  if (n > kI) {
    P_.bottomLeftCorner(n - kI, kI) = cols.bottomRows(n - kI);
    P_.topRightCorner(kI, n - kI) = cols.bottomRows(n - kI).transpose();
  }
  for (const StateBlock& b : layout_.blocks()) {
    const double sigma = random_walks_.of(b.kind);
    if (sigma <= 0.0 || b.kind == kindOf<ImuKind>) continue;  // the IMU's noise is Q
    for (int i = b.offset; i < b.offset + b.dim; ++i) P_(i, i) += sigma * sigma * dt;
  }
  checkInvariants("propagate");
}

void CentralizedEkf::addImuNoise(const ImuMatrix& Q) {
  P_.topLeftCorner<ImuErr::kDim, ImuErr::kDim>() += 0.5 * (Q + Q.transpose());  // the IMU block is first
  checkInvariants("addImuNoise");
}

UpdateResult CentralizedEkf::update(const Linearization& lin, double nis_gate) {
  const DenseUpdateOutput out = denseEkfUpdate(P_, layout_, lin, nis_gate, joseph_form_);
  UpdateResult res;
  res.nis = out.nis;
  if (!out.accepted) return res;
  x_.boxplus(layout_, out.dx);
  res.accepted = true;
  checkInvariants("update");
  return res;
}

Eigen::MatrixXd CentralizedEkf::covariance(SensorId a, SensorId b) const {
  const StateBlock& ba = layout_.at(a);
  const StateBlock& bb = layout_.at(b);
  return P_.block(ba.offset, bb.offset, ba.dim, bb.dim);
}

void CentralizedEkf::checkInvariants() const {
  if (!(P_ - P_.transpose()).isZero(1e-9 * (1.0 + P_.norm())))
    throw std::logic_error("CentralizedEkf: covariance not symmetric");
  if (P_.size() && Eigen::LLT<Eigen::MatrixXd>(P_).info() != Eigen::Success)
    throw std::logic_error("CentralizedEkf: covariance not positive definite");
}

void CentralizedEkf::checkInvariants(const char* where) const {
#ifdef MESHNAV_CHECK_INVARIANTS
  if (!(P_ - P_.transpose()).isZero(1e-9 * (1.0 + P_.norm())))
    throw std::logic_error(std::string("CentralizedEkf: covariance not symmetric after ") + where);
  if (Eigen::LLT<Eigen::MatrixXd>(P_).info() != Eigen::Success)
    throw std::logic_error(std::string("CentralizedEkf: covariance not positive definite after ") + where);
#else
  (void)where;
#endif
}

}  // namespace meshnav::estimator
