/// @file flight_volume_guard.cpp
/// @brief FlightVolumeGuard: mirror image and side truncation (flight_volume_guard.h).

#include "estimator/health/flight_volume_guard.h"

#include <spdlog/spdlog.h>

namespace meshnav::estimator {

FlightVolumeGuard::FlightVolumeGuard(const FlightVolumeOptions& options, const SystemSetup& setup, Diagnostics& diag)
    : options_(options), volume_(setup.flight_volume), diag_(diag) {
  if (setup.flight_volume && options.enabled)
    mirror_ = AnchorPlaneMirror::of(setup.abs_anchor_positions, *setup.flight_volume);
}

std::optional<FlightVolumeGuard::Reflected> FlightVolumeGuard::mirrorImage(Timestamp t, const ImuState& x,
                                                                           const ImuMatrix& P) const {
  if (!isMirrorImage(x.p_IinG)) return std::nullopt;
  Reflected m{x, P};
  m.x.p_IinG = mirror_->mirror(x.p_IinG);
  m.x.v_IinG = mirror_->reflection() * x.v_IinG;
  ImuMatrix J = ImuMatrix::Identity();
  J.block<3, 3>(ImuErr::kP, ImuErr::kP) = mirror_->reflection();
  J.block<3, 3>(ImuErr::kV, ImuErr::kV) = mirror_->reflection();
  m.P = J * P * J.transpose();
  diag_.count("mirrored_into_flight_volume");
  spdlog::warn("estimator: at t={} the estimate [{:.2f}, {:.2f}, {:.2f}] m is {:.2f} m outside the flight volume and "
               "its mirror image across the known anchors' plane is inside: taken as the mirror image (moved {:.2f} m)",
               formatSeconds(t), x.p_IinG.x(), x.p_IinG.y(), x.p_IinG.z(), volume_->distanceOutside(x.p_IinG),
               (m.x.p_IinG - x.p_IinG).norm());
  return m;
}

bool FlightVolumeGuard::sideConstraintDue(Timestamp t) const {
  const double rate = options_.side_constraint_rate_hz;
  return mirror_ && rate > 0.0 && (!last_side_constraint_ || (t - *last_side_constraint_).sec() >= 1.0 / rate - 1e-9);
}

std::optional<Linearization> FlightVolumeGuard::sideConstraint(Timestamp t, SensorId imu_id,
                                                               const Eigen::Vector3d& p_IinG,
                                                               const Eigen::Matrix3d& P_pp) {
  if (!sideConstraintDue(t)) return std::nullopt;
  last_side_constraint_ = t;
  const Eigen::Vector3d n = mirror_->inwardNormal();
  const double mu = mirror_->inwardDistance(p_IinG);
  const auto c = AnchorPlaneMirror::sideConstraint(mu, n.dot(P_pp * n));
  if (!c) return std::nullopt;
  Linearization lin;  // r = z − nᵀ(p̂ − c_plane), H = nᵀ on δp
  lin.residual = Eigen::VectorXd::Constant(1, c->z - mu);
  lin.R = Eigen::MatrixXd::Constant(1, 1, c->R);
  JacobianBlock b{imu_id, Eigen::MatrixXd::Zero(1, ImuErr::kDim)};
  b.H.block<1, 3>(0, ImuErr::kP) = n.transpose();
  lin.blocks.push_back(std::move(b));
  diag_.count("flight_volume_side_constraint");
  return lin;
}

}  // namespace meshnav::estimator
