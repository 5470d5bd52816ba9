#include "estimator/filter/modular_filter.h"

#include <stdexcept>

namespace meshnav::estimator {

ModularFilter::ModularFilter(Mode mode, const ImuPropagator& propagator, double baro_bias_rw_m_per_sqrt_s,
                             bool joseph_form, double height_bias_rw_m_per_sqrt_s)
    : propagator_(propagator),
      baro_bias_rw_(baro_bias_rw_m_per_sqrt_s),
      height_bias_rw_(height_bias_rw_m_per_sqrt_s),
      cov_(mode, joseph_form) {}

void ModularFilter::checkAfter(const char* where) const {
#ifdef MESHNAV_CHECK_INVARIANTS
  cov_.checkInvariants(where);
#else
  (void)where;
#endif
}

void ModularFilter::reset(SensorId imu_id, const ImuState& x, const ImuMatrix& cov, Timestamp t) {
  x_ = NominalState{};
  x_.t = t;
  x_.imu_id = imu_id;
  x_.imu = x;
  cov_ = FactorizedCovariance(cov_.mode(), cov_.josephForm());
  cov_.add(imu_id, InstanceKind::Imu, cov, t);
}

void ModularFilter::addBaro(SensorId id, double bias_m, double var_m2) {
  if (cov_.has(id)) removeInstance(id);
  x_.baro_bias_m[id] = bias_m;
  cov_.add(id, InstanceKind::Baro, Eigen::MatrixXd::Constant(1, 1, var_m2), x_.t);
}

void ModularFilter::addHeight(SensorId id, double bias_m, double var_m2) {
  if (cov_.has(id)) removeInstance(id);
  x_.height_bias_m[id] = bias_m;
  cov_.add(id, InstanceKind::Height, Eigen::MatrixXd::Constant(1, 1, var_m2), x_.t);
}

void ModularFilter::addAnchor(SensorId id, const Eigen::Vector3d& p_AinG, const Eigen::MatrixXd& cov,
                              const BiasState& biases) {
  checkAnchorBlock(id, cov, biases);
  if (cov_.has(id)) removeInstance(id);
  x_.anchor_p_AinG[id] = p_AinG;
  if (!biases.peers.empty()) x_.anchor_biases[id] = biases;
  cov_.add(id, InstanceKind::Anchor, cov, x_.t);
}

void ModularFilter::addTagBiases(SensorId tag_id, const std::vector<SensorId>& peers, const Eigen::VectorXd& gamma_m,
                                 const Eigen::VectorXd& var_m2) {
  if (cov_.has(tag_id)) removeInstance(tag_id);
  x_.tag_biases[tag_id] = BiasState{peers, gamma_m};
  cov_.add(tag_id, InstanceKind::Tag, var_m2.asDiagonal().toDenseMatrix(), x_.t);
}

bool ModularFilter::removeInstance(SensorId id) {
  if (!cov_.has(id) || cov_.layout().at(id).kind == InstanceKind::Imu) return false;
  cov_.remove(id);
  x_.erase(id);
  return true;
}

void ModularFilter::propagate(const Eigen::Vector3d& acc_m_s2, const Eigen::Vector3d& gyro_rad_s, Timestamp t_to) {
  const double dt = (t_to - x_.t).sec();
  if (dt <= 0.0) return;
  ImuMatrix Phi, Q;
  propagator_.propagate(x_.imu, acc_m_s2, gyro_rad_s, dt, &Phi, &Q);
  x_.t = t_to;
  cov_.propagate(x_.imu_id, Phi, Q, t_to);
  if (baro_bias_rw_ > 0.0)
    for (const auto& [id, b] : x_.baro_bias_m)
      cov_.addNoise(id, Eigen::MatrixXd::Constant(1, 1, baro_bias_rw_ * baro_bias_rw_ * dt), t_to);
  if (height_bias_rw_ > 0.0)
    for (const auto& [id, b] : x_.height_bias_m)
      cov_.addNoise(id, Eigen::MatrixXd::Constant(1, 1, height_bias_rw_ * height_bias_rw_ * dt), t_to);
  checkAfter("propagate");
}

void ModularFilter::addImuNoise(const ImuMatrix& Q) {
  cov_.addNoise(x_.imu_id, 0.5 * (Q + Q.transpose()), x_.t);
  checkAfter("addImuNoise");
}

UpdateResult ModularFilter::update(const Linearization& lin, double nis_gate) {
  const FactorizedCovariance::Result r = cov_.update(lin, nis_gate, x_.t);
  UpdateResult res;
  res.nis = r.nis;
  if (!r.accepted) return res;
  for (const StateBlock& b : r.blocks) x_.boxplusBlock(b, r.dx.segment(b.offset, b.dim));
  res.accepted = true;
  checkAfter("update");
  return res;
}

}  // namespace meshnav::estimator
