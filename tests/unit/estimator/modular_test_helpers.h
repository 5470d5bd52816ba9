#pragma once
/// @file modular_test_helpers.h
/// @brief Relative comparison of two strategies' estimates (means and marginal covariances) and
/// arrival shuffling, for the DP/DAH tests.

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "estimator/node/estimator_node.h"

namespace meshnav::estimator::test {

/// Largest relative difference of the nominal states (|Δ| / (1 + |x|), Δ = x ⊟ y per instance of
/// every registered kind) and of the marginal covariances Σ_ii of every instance with state
/// (max|ΔΣ_ii| / max|Σ_ii|). Layouts must match.
inline double relativeDifference(const FusionStrategy& a, const FusionStrategy& b) {
  const NominalState &x = a.state(), &y = b.state();
  if (x.t != y.t || a.layout().blocks().size() != b.layout().blocks().size()) return 1e300;
  double d = 0.0;
  auto rel = [&](double dv, double v) { d = std::max(d, std::abs(dv) / (1.0 + std::abs(v))); };
  const ImuVector dimu = x.imu.boxminus(y.imu);
  for (int i = 0; i < 3; ++i) {
    rel(dimu(ImuErr::kP + i), y.imu.p_IinG(i));
    rel(dimu(ImuErr::kV + i), y.imu.v_IinG(i));
    rel(dimu(ImuErr::kTheta + i), 1.0);
    rel(dimu(ImuErr::kBg + i), y.imu.bias_gyro_rad_s(i));
    rel(dimu(ImuErr::kBa + i), y.imu.bias_acc_m_s2(i));
  }
  // Every other registered kind: its ⊟ against its value's vector form (the same size as its
  // error state for every kind but the body).
  bool mismatch = false;
  forEachKind([&]<class K>() {
    if constexpr (!K::kBody) {
      for (const auto& [id, v] : x.values<K>()) {
        const auto it = y.values<K>().find(id);
        if (it == y.values<K>().end() || K::peersOf(v) != K::peersOf(it->second)) {
          mismatch = true;
          continue;
        }
        const Eigen::VectorXd dv = K::boxminus(v, it->second), mag = K::toVector(v);
        for (Eigen::Index i = 0; i < dv.size(); ++i) rel(dv(i), mag(i));
      }
    }
  });
  if (mismatch) return 1e300;
  for (const StateBlock& blk : a.layout().blocks()) {
    if (!b.layout().find(blk.id)) return 1e300;
    const Eigen::MatrixXd Pa = a.covariance(blk.id, blk.id), Pb = b.covariance(blk.id, blk.id);
    d = std::max(d, (Pa - Pb).cwiseAbs().maxCoeff() / Pb.cwiseAbs().maxCoeff());
  }
  return d;
}

/// Arrival order: ranges and baro (other processes) delayed by U(0, max_delay_s) after `after_s`.
inline std::vector<EstimatorInput> shuffledArrival(const std::vector<EstimatorInput>& inputs, double max_delay_s,
                                                   double after_s, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> delay(0.0, max_delay_s);
  std::vector<std::pair<double, EstimatorInput>> arrivals;
  for (const auto& in : inputs) {
    double dl = 0.0;
    const bool other = std::holds_alternative<RangeSample>(in) || std::holds_alternative<BaroSample>(in);
    if (other && inputTime(in).sec() > after_s) dl = delay(rng);
    arrivals.emplace_back(inputTime(in).sec() + dl, in);
  }
  std::stable_sort(arrivals.begin(), arrivals.end(), [](const auto& p, const auto& q) { return p.first < q.first; });
  std::vector<EstimatorInput> out;
  for (auto& [t, in] : arrivals) out.push_back(std::move(in));
  return out;
}

/// A linearized range between the IMU (`x.imu_id`, tag at its origin) and anchor `a` of `x`,
/// measured as `z` (σ 0.1 m).
inline Linearization imuAnchorRange(const NominalState& x, SensorId a, double z) {
  const Eigen::Vector3d d = x.values<AnchorKind>().at(a).p_AinG - x.imu.p_IinG;
  Linearization lin;
  lin.residual = Eigen::VectorXd::Constant(1, z - d.norm());
  lin.R = Eigen::MatrixXd::Constant(1, 1, 0.01);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(1, 15);
  H.block<1, 3>(0, ImuErr::kP) = -d.normalized().transpose();
  lin.blocks.push_back({x.imu_id, H});
  lin.blocks.push_back({a, Eigen::MatrixXd(d.normalized().transpose())});
  return lin;
}

/// A linearized range between anchors `a` and `b` of `x`, measured as `z` (σ 0.1 m).
inline Linearization anchorPairRange(const NominalState& x, SensorId a, SensorId b, double z) {
  const Eigen::Vector3d d = x.values<AnchorKind>().at(b).p_AinG - x.values<AnchorKind>().at(a).p_AinG;
  Linearization lin;
  lin.residual = Eigen::VectorXd::Constant(1, z - d.norm());
  lin.R = Eigen::MatrixXd::Constant(1, 1, 0.01);
  lin.blocks.push_back({a, Eigen::MatrixXd(-d.normalized().transpose())});
  lin.blocks.push_back({b, Eigen::MatrixXd(d.normalized().transpose())});
  return lin;
}

inline EstimatorOptions strategyOptions(const std::string& strategy) {
  EstimatorOptions o;
  o.window_s = 1.0;
  o.strategy = strategy;
  return o;
}

}  // namespace meshnav::estimator::test
