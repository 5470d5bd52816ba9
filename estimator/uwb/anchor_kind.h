#pragma once
/// @file anchor_kind.h
/// @brief Instance kind of an estimated anchor (estimator/core/kind_traits.h): its position
/// p_AinG [m] (error state δp, 3) followed by its pair biases γ towards its peers (one error state
/// each, γ = γ̂ + δγ), constant.

#include <Eigen/Core>
#include <utility>

#include "estimator/core/estimator_options.h"
#include "estimator/core/kind_traits.h"
#include "estimator/uwb/bias_state.h"

namespace meshnav::estimator {

/// Nominal value of an estimated anchor.
struct AnchorState {
  AnchorState() = default;
  explicit AnchorState(const Eigen::Vector3d& p, BiasState b = {}) : p_AinG(p), biases(std::move(b)) {}
  Eigen::Vector3d p_AinG = Eigen::Vector3d::Zero();  ///< [m]
  BiasState biases;                                  ///< no peers: no γ states
};

struct AnchorKind {
  static constexpr const char* kName = "anchor";
  static constexpr int kDim = 3;
  static constexpr bool kBody = false;
  using Value = AnchorState;
  static void boxplus(Value& a, const Eigen::Ref<const Eigen::VectorXd>& dx) {
    a.p_AinG += dx.template head<3>();
    if (dx.size() > 3) a.biases.gamma_m += dx.segment(3, dx.size() - 3);
  }
  static Eigen::VectorXd boxminus(const Value& a, const Value& ref) {
    requireSameStates(kName, a.biases.gamma_m.size(), ref.biases.gamma_m.size());
    Eigen::VectorXd d(3 + a.biases.gamma_m.size());
    d << a.p_AinG - ref.p_AinG, a.biases.gamma_m - ref.biases.gamma_m;
    return d;
  }
  /// The joint covariance of [p_AinG, γ] must be (3 + #peers)² and γ hold one value per peer.
  static void check(SensorId id, const Value& a, const Eigen::MatrixXd& cov) {
    const auto k = static_cast<Eigen::Index>(a.biases.peers.size());
    if (a.biases.gamma_m.size() != k || cov.rows() != 3 + k || cov.cols() != 3 + k)
      throw std::invalid_argument("add anchor " + std::to_string(id) + ": covariance " + std::to_string(cov.rows()) +
                                  "x" + std::to_string(cov.cols()) + " does not fit 3 + " + std::to_string(k) +
                                  " bias states (" + std::to_string(a.biases.gamma_m.size()) + " values)");
  }
  static double randomWalk(const EstimatorOptions&) { return 0.0; }
  static Eigen::MatrixXd keptCovariance(const Eigen::MatrixXd& cov, const EstimatorOptions&) { return cov; }
  /// A restart replays the anchors as calibration results (ANCHOR_INIT), which also restores the
  /// UWB network's side of them (calibrated, pair biases that are not states).
  static Restart restart(const EstimatorOptions&) { return Restart::kCalibration; }
  /// [p_AinG, γ_1 … γ_n] towards `peers`.
  static Eigen::VectorXd toVector(const Value& a) {
    Eigen::VectorXd x(3 + a.biases.gamma_m.size());
    x << a.p_AinG, a.biases.gamma_m;
    return x;
  }
  static std::vector<SensorId> peersOf(const Value& a) { return a.biases.peers; }
  static Value fromVector(const Eigen::VectorXd& x, const std::vector<SensorId>& peers) {
    requireVectorSize(kName, x.size(), 3 + static_cast<Eigen::Index>(peers.size()));
    return AnchorState{x.head<3>(), BiasState{peers, x.tail(x.size() - 3)}};
  }
};

}  // namespace meshnav::estimator
