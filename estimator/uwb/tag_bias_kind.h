#pragma once
/// @file tag_bias_kind.h
/// @brief Instance kind of a tag whose constant biases γ(tag, peer) towards exactly known anchors
/// are estimated (estimator/core/kind_traits.h): one error state per peer, γ = γ̂ + δγ.

#include <Eigen/Core>

#include "estimator/core/estimator_options.h"
#include "estimator/core/kind_traits.h"
#include "estimator/uwb/bias_state.h"

namespace meshnav::estimator {

struct TagBiasKind {
  static constexpr const char* kName = "tag";
  static constexpr int kDim = 0;  // one per peer
  static constexpr bool kBody = false;
  using Value = BiasState;
  static void boxplus(Value& g, const Eigen::Ref<const Eigen::VectorXd>& dx) { g.gamma_m += dx; }
  static Eigen::VectorXd boxminus(const Value& g, const Value& ref) {
    requireSameStates(kName, g.gamma_m.size(), ref.gamma_m.size());
    return g.gamma_m - ref.gamma_m;
  }
  static void check(SensorId id, const Value& g, const Eigen::MatrixXd& cov) {
    if (g.gamma_m.size() != static_cast<Eigen::Index>(g.peers.size()))
      throw std::invalid_argument("add tag " + std::to_string(id) + ": " + std::to_string(g.gamma_m.size()) +
                                  " γ values for " + std::to_string(g.peers.size()) + " peers");
    requireBlockSize(kName, id, cov, g.gamma_m.size());
  }
  static double randomWalk(const EstimatorOptions&) { return 0.0; }
  /// A recovery keeps the variances only (as the prior: uncorrelated γ).
  static Eigen::MatrixXd keptCovariance(const Eigen::MatrixXd& cov, const EstimatorOptions&) {
    return cov.diagonal().asDiagonal().toDenseMatrix();
  }
  /// A restart keeps the estimated γ and their covariance (constant biases: what was learnt holds).
  static Restart restart(const EstimatorOptions& o) {
    return o.uwb.estimate_tag_biases ? Restart::kKept : Restart::kPrior;
  }
  /// [γ_1 … γ_n] towards `peers`.
  static Eigen::VectorXd toVector(const Value& g) { return g.gamma_m; }
  static std::vector<SensorId> peersOf(const Value& g) { return g.peers; }
  static Value fromVector(const Eigen::VectorXd& x, const std::vector<SensorId>& peers) {
    requireVectorSize(kName, x.size(), static_cast<Eigen::Index>(peers.size()));
    return BiasState{peers, x};
  }
};

}  // namespace meshnav::estimator
