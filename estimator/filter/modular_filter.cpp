#include "estimator/filter/modular_filter.h"

#include <stdexcept>

namespace meshnav::estimator {

ModularFilter::ModularFilter(Mode mode, const ImuPropagator& propagator, const KindRandomWalks& random_walks,
                             bool joseph_form)
    : propagator_(propagator), random_walks_(random_walks), cov_(mode, joseph_form) {}

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
  cov_.add(imu_id, kindOf<ImuKind>, cov, t);
}

bool ModularFilter::removeInstance(SensorId id) {
  if (!cov_.has(id) || cov_.layout().at(id).kind == kindOf<ImuKind>) return false;
  cov_.remove(id);
  x_.erase(id);
  return true;
}

void ModularFilter::propagate(const Eigen::Vector3d& acc_m_s2, const Eigen::Vector3d& gyro_rad_s, Timestamp t_to) {
  const double dt = (t_to - x_.t).sec();
  if (dt <= 0.0) return;
  ImuMatrix Phi, Q;
  propagator_.propagate(x_.imu, acc_m_s2, gyro_rad_s, dt, &Phi, &Q);
  noteTransition(Phi);
  x_.t = t_to;
  cov_.propagate(x_.imu_id, Phi, Q, t_to);
  // Kind by kind in registry order, instances by id: Σ_kk += σ_k² Δt I.
  forEachKind([&]<class K>() {
    if constexpr (!K::kBody) {
      const double sigma = random_walks_.of(kindOf<K>);
      if (sigma <= 0.0) return;
      for (const auto& [id, value] : x_.values<K>()) {
        const int d = cov_.layout().at(id).dim;
        cov_.addNoise(id, Eigen::MatrixXd::Identity(d, d) * (sigma * sigma * dt), t_to);
      }
    }
  });
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
