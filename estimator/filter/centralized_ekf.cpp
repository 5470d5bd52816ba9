#include "estimator/filter/centralized_ekf.h"

#include "estimator/filter/dense_ekf_update.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <stdexcept>

namespace meshnav::estimator {

CentralizedEkf::CentralizedEkf(const ImuPropagator& propagator, double baro_bias_rw_m_per_sqrt_s, bool joseph_form,
                               double height_bias_rw_m_per_sqrt_s)
    : propagator_(propagator),
      baro_bias_rw_(baro_bias_rw_m_per_sqrt_s),
      height_bias_rw_(height_bias_rw_m_per_sqrt_s),
      joseph_form_(joseph_form) {}

void CentralizedEkf::reset(SensorId imu_id, const ImuState& x, const ImuMatrix& cov, Timestamp t) {
  x_ = NominalState{};
  x_.t = t;
  x_.imu_id = imu_id;
  x_.imu = x;
  layout_ = StateLayout{};
  P_.resize(0, 0);
  appendBlock(imu_id, InstanceKind::Imu, cov);
}

void CentralizedEkf::appendBlock(SensorId id, InstanceKind kind, const Eigen::MatrixXd& cov) {
  const int n = layout_.dim();
  const StateBlock& b = layout_.add(id, kind, static_cast<int>(cov.rows()));
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(layout_.dim(), layout_.dim());
  P.topLeftCorner(n, n) = P_;
  P.block(b.offset, b.offset, b.dim, b.dim) = 0.5 * (cov + cov.transpose());
  P_ = std::move(P);
}

void CentralizedEkf::addBaro(SensorId id, double bias_m, double var_m2) {
  if (layout_.find(id)) removeInstance(id);
  x_.baro_bias_m[id] = bias_m;
  appendBlock(id, InstanceKind::Baro, Eigen::MatrixXd::Constant(1, 1, var_m2));
}

void CentralizedEkf::addHeight(SensorId id, double bias_m, double var_m2) {
  if (layout_.find(id)) removeInstance(id);
  x_.height_bias_m[id] = bias_m;
  appendBlock(id, InstanceKind::Height, Eigen::MatrixXd::Constant(1, 1, var_m2));
}

void CentralizedEkf::addAnchor(SensorId id, const Eigen::Vector3d& p_AinG, const Eigen::MatrixXd& cov,
                               const BiasState& biases) {
  checkAnchorBlock(id, cov, biases);
  if (layout_.find(id)) removeInstance(id);
  x_.anchor_p_AinG[id] = p_AinG;
  if (!biases.peers.empty()) x_.anchor_biases[id] = biases;
  appendBlock(id, InstanceKind::Anchor, cov);
}

void CentralizedEkf::addTagBiases(SensorId tag_id, const std::vector<SensorId>& peers, const Eigen::VectorXd& gamma_m,
                                  const Eigen::VectorXd& var_m2) {
  if (layout_.find(tag_id)) removeInstance(tag_id);
  x_.tag_biases[tag_id] = BiasState{peers, gamma_m};
  appendBlock(tag_id, InstanceKind::Tag, var_m2.asDiagonal().toDenseMatrix());
}

bool CentralizedEkf::removeInstance(SensorId id) {
  const StateBlock* blk = layout_.find(id);
  if (!blk || blk->kind == InstanceKind::Imu) return false;
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
  x_.t = t_to;
  constexpr int kI = ImuErr::kDim;  // the IMU block is always first
  const int n = layout_.dim();
  // P ← Φ_full P Φ_fullᵀ with Φ_full = diag(Φ, I): rows, then columns.
  P_.topRows<kI>() = (Phi * P_.topRows<kI>()).eval();
  P_.leftCols<kI>() = (P_.leftCols<kI>() * Phi.transpose()).eval();
  P_.topLeftCorner<kI, kI>() += Q;
  // Keep the touched rows/columns exactly symmetric.
  const ImuMatrix Pii = P_.topLeftCorner<kI, kI>();
  P_.topLeftCorner<kI, kI>() = 0.5 * (Pii + Pii.transpose());
  if (n > kI) P_.bottomLeftCorner(n - kI, kI) = P_.topRightCorner(kI, n - kI).transpose();
  for (const StateBlock& b : layout_.blocks())
    if (b.kind == InstanceKind::Baro)
      P_(b.offset, b.offset) += baro_bias_rw_ * baro_bias_rw_ * dt;
    else if (b.kind == InstanceKind::Height)
      P_(b.offset, b.offset) += height_bias_rw_ * height_bias_rw_ * dt;
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
