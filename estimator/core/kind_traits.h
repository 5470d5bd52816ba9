#pragma once
/// @file kind_traits.h
/// @brief What a kind of sensor instance with state tells the filter (paper §III-A), and the
/// type list the registry (estimator/core/instance_kind.h) is made of.
///
/// A kind is a struct in its sensor's folder (e.g. estimator/baro/baro_bias_kind.h) with
///   - `kName`       its name in EstimatorStatus ("baro"),
///   - `kDim`        its default error-state dimension (0: given by the covariance at insertion),
///   - `kBody`       true only for the IMU: the one body instance, held in NominalState::imu,
///   - `Value`       its nominal value (e.g. a bias b [m]),
///   - `boxplus(v, δx)`            v ← v ⊞ δx for an error-state correction of the block's size,
///   - `boxminus(v, v̂)`            δx = v ⊟ v̂ (v = v̂ ⊞ δx; both with the same states),
///   - `check(id, v, Σ)`           throws std::invalid_argument unless Σ fits v,
///   - `randomWalk(options)`       σ [unit/√s] of a random walk on every error state (Σ += σ² Δt I
///                                 per propagation; 0: constant),
///   - `keptCovariance(Σ, options)` its covariance when a recovery re-creates the filter around a
///                                 new IMU state (keeps the mean; may widen Σ),
///   - `restart(options)`          what a restart keeps of it (Restart below; docs/robustness.md
///                                 "Restarts"),
///   - `toVector(v)`, `peersOf(v)`, `fromVector(x, peers)`  its value as a list of numbers (and the
///                                 peer ids of per-peer states) for the restart checkpoint
///                                 (estimator/restart/checkpoint.h); fromVector throws
///                                 std::invalid_argument on a list that does not fit.
/// A kind whose state is one number derives `kDim`, `kBody`, `Value`, `boxplus`, `boxminus`,
/// `check` and the vector form from ScalarStateKind (below). The strategies, NominalState and the node's recovery iterate over the
/// registry; none of them names a kind other than the IMU.

#include <Eigen/Core>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "common/types.h"

namespace meshnav::estimator {

/// What a restart of the estimator process keeps of a kind's instances (K::restart(options)).
enum class Restart {
  kBody,         ///< the IMU: the pose across a short outage only (init.resume_max_outage_s)
  kKept,         ///< value and marginal covariance, whatever the outage (Σ grown by the random walk)
  kCalibration,  ///< kept as a calibration result and replayed through ANCHOR_INIT (the anchors:
                 ///< the UWB network's side, calibrated flag and pair-bias dictionary, comes too)
  kPrior,        ///< not kept: starts again from its prior
};

/// An ordered list of kinds (the order is the registry's: it fixes how a recovery re-adds them).
template <class... K>
struct KindList {
  static constexpr int kCount = sizeof...(K);
};

namespace detail {
template <class T, class... K>
constexpr int kindIndex(KindList<K...>) {
  int i = 0, found = -1;
  ((std::is_same_v<T, K> ? (found = i, ++i) : ++i), ...);
  return found;
}
template <class F, class... K>
void forEach(KindList<K...>, F&& f) {
  (f.template operator()<K>(), ...);
}
}  // namespace detail

/// Throws std::invalid_argument unless two values of kind `kind` have the same number of states
/// (`n`, `n_ref`), as ⊟ needs.
inline void requireSameStates(const char* kind, Eigen::Index n, Eigen::Index n_ref) {
  if (n != n_ref)
    throw std::invalid_argument(std::string("boxminus ") + kind + ": " + std::to_string(n) + " states against " +
                                std::to_string(n_ref));
}

/// Throws std::invalid_argument unless `cov` is `dim`×`dim` (the covariance offered for a new
/// instance `id` of kind `kind`).
inline void requireBlockSize(const char* kind, SensorId id, const Eigen::MatrixXd& cov, Eigen::Index dim) {
  if (cov.rows() != dim || cov.cols() != dim)
    throw std::invalid_argument(std::string("add ") + kind + " " + std::to_string(id) + ": covariance " +
                                std::to_string(cov.rows()) + "x" + std::to_string(cov.cols()) + ", expected " +
                                std::to_string(dim) + "x" + std::to_string(dim));
}

/// Throws std::invalid_argument unless a checkpoint's list of `n` numbers holds `expected` for a
/// value of kind `kind`.
inline void requireVectorSize(const char* kind, Eigen::Index n, Eigen::Index expected) {
  if (n != expected)
    throw std::invalid_argument(std::string(kind) + ": " + std::to_string(n) + " numbers, expected " +
                                std::to_string(expected));
}

/// Base of a kind whose state is one number v = v̂ + δv (a bias, a scale factor): `kDim`, `kBody`,
/// `Value`, `boxplus`, `boxminus`, `check` and the vector form [v]; the kind adds `kName`,
/// `randomWalk`, `keptCovariance` and `restart`.
template <class Kind>
struct ScalarStateKind {
  static constexpr int kDim = 1;
  static constexpr bool kBody = false;
  using Value = double;
  static void boxplus(Value& v, const Eigen::Ref<const Eigen::VectorXd>& dx) { v += dx(0); }
  static Eigen::VectorXd boxminus(const Value& v, const Value& ref) { return Eigen::VectorXd::Constant(1, v - ref); }
  static void check(SensorId id, const Value&, const Eigen::MatrixXd& cov) {
    requireBlockSize(Kind::kName, id, cov, kDim);
  }
  static Eigen::VectorXd toVector(const Value& v) { return Eigen::VectorXd::Constant(1, v); }
  static std::vector<SensorId> peersOf(const Value&) { return {}; }
  static Value fromVector(const Eigen::VectorXd& x, const std::vector<SensorId>& peers) {
    requireVectorSize(Kind::kName, x.size(), 1);
    if (!peers.empty()) throw std::invalid_argument(std::string(Kind::kName) + ": has no peers");
    return x(0);
  }
};

}  // namespace meshnav::estimator
