#include "estimator/filter/centralized_ekf.h"

#include "estimator/filter/dense_ekf_update.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <stdexcept>

namespace meshnav::estimator {

namespace {

/// The IMU transition Φ by 3 × 3 blocks (ImuPropagator: identity on the diagonal but for θθ, ten of
/// the 25 blocks zero, the bias rows the identity): Φ M costs 81 of the 225 multiply-adds per column
/// a dense product takes, with no packing. Each block's type is read from Φ, so any Φ is exact.
class BlockSparseImuMatrix {
 public:
  explicit BlockSparseImuMatrix(const ImuMatrix& Phi) {
    for (int i = 0; i < kB; ++i) {
      first_[i] = n_blocks_;
      for (int j = 0; j < kB; ++j) {
        const auto b = Phi.block<3, 3>(3 * i, 3 * j);
        if (b.isZero(0.0)) continue;
        Block& e = blocks_[n_blocks_++];
        e.col = 3 * j;
        e.identity = b.isIdentity(0.0);
        for (int r = 0; r < 3; ++r)
          for (int k = 0; k < 3; ++k) e.a[r][k] = b(r, k);
      }
    }
    first_[kB] = n_blocks_;
  }
  /// out = Φ M for a 15-row M.
  template <typename Derived>
  void times(const Eigen::MatrixBase<Derived>& M, Eigen::Matrix<double, ImuErr::kDim, Eigen::Dynamic>& out) const {
    out.resize(ImuErr::kDim, M.cols());
    for (Eigen::Index c = 0; c < M.cols(); ++c) {
      double m[ImuErr::kDim];
      for (int k = 0; k < ImuErr::kDim; ++k) m[k] = M(k, c);
      double* o = out.col(c).data();
      for (int i = 0; i < kB; ++i) {  // block row i: its blocks are blocks_[first_[i], first_[i + 1])
        double y0 = 0.0, y1 = 0.0, y2 = 0.0;
        for (int b = first_[i]; b < first_[i + 1]; ++b) {
          const Block& e = blocks_[b];
          const double* x = m + e.col;
          if (e.identity) {
            y0 += x[0];
            y1 += x[1];
            y2 += x[2];
          } else {
            y0 += e.a[0][0] * x[0] + e.a[0][1] * x[1] + e.a[0][2] * x[2];
            y1 += e.a[1][0] * x[0] + e.a[1][1] * x[1] + e.a[1][2] * x[2];
            y2 += e.a[2][0] * x[0] + e.a[2][1] * x[1] + e.a[2][2] * x[2];
          }
        }
        o[3 * i] = y0;
        o[3 * i + 1] = y1;
        o[3 * i + 2] = y2;
      }
    }
  }

 private:
  static constexpr int kB = ImuErr::kDim / 3;
  struct Block {
    int col = 0;
    bool identity = false;
    double a[3][3] = {};
  };
  Block blocks_[kB * kB];  ///< the nonzero blocks by block row
  int first_[kB + 1] = {};
  int n_blocks_ = 0;
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
  // P ← Φ_full P Φ_fullᵀ with Φ_full = diag(Φ, I): the IMU rows Φ P_I· (their blocks P_Ij,
  // j ≠ I, are final), then the IMU block (Φ P_II) Φᵀ + Q; the IMU columns below it are the
  // transpose of its rows. (The columns' product over all n rows, as before, computed rows that
  // the transpose then overwrote: 15 × 15 × n multiplications a step for nothing.)
  const BlockSparseImuMatrix phi(Phi);
  auto& rows = scratch_.rows;
  phi.times(P_.topRows<kI>(), rows);
  P_.topRows<kI>() = rows;
  Eigen::Matrix<double, kI, Eigen::Dynamic> PiiT;  // (Φ P_II) Φᵀ = (Φ (Φ P_II)ᵀ)ᵀ
  phi.times(rows.leftCols<kI>().transpose(), PiiT);
  ImuMatrix Pii = PiiT.transpose();
  Pii += Q;
  // Keep the touched rows/columns exactly symmetric.
  P_.topLeftCorner<kI, kI>() = 0.5 * (Pii + Pii.transpose());
  if (n > kI) P_.bottomLeftCorner(n - kI, kI) = P_.topRightCorner(kI, n - kI).transpose();
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
