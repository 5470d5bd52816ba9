#pragma once
/// @file node_test_helpers.h
/// @brief Running an EstimatorNode over synthetic data and comparing filter states.

#include <gtest/gtest.h>

#include "estimator/node/estimator_node.h"
#include "estimator/testing/synthetic_scenario.h"

namespace meshnav::estimator::test {

/// Max absolute difference of the nominal states and covariances of two filters.
inline double stateDifference(const FusionStrategy& a, const FusionStrategy& b) {
  const NominalState &x = a.state(), &y = b.state();
  if (x.t != y.t || a.layout().dim() != b.layout().dim()) return 1e300;
  // Every instance of every registered kind (x ⊟ y over a's layout).
  double d = x.boxminus(y, a.layout()).cwiseAbs().maxCoeff();
  return std::max(d, (a.fullCovariance() - b.fullCovariance()).cwiseAbs().maxCoeff());
}

/// A short noisy flight (10 s, landed for the first 3 s): the scenario of the bad-input tests.
inline synthetic::SyntheticOptions shortNoisyFlight(uint32_t seed) {
  synthetic::SyntheticOptions o;
  o.duration_s = 10.0;
  o.landed_s = 3.0;
  o.noise = true;
  o.seed = seed;
  return o;
}

/// 30 s of the noisy synthetic flight (seed 4) with the first `n` estimated anchors (106, ...)
/// unknown to the setup; their ranges stay in the data (the anchor re-run tests).
inline Dataset flightWithUnknownAnchors(int n) {
  synthetic::SyntheticOptions o;
  o.duration_s = 30.0;
  o.noise = true;
  o.seed = 4;
  o.n_estimated_anchors = n;
  Dataset ds = synthetic::makeSyntheticDataset(o);
  for (SensorId id = 106; id < 106 + n; ++id) {
    ds.setup.abs_anchor_positions.erase(id);
    ds.setup.abs_anchor_sigmas_m.erase(id);
  }
  return ds;
}

inline EstimatorOptions testOptions() {
  EstimatorOptions o;
  o.window_s = 1.0;
  return o;
}

}  // namespace meshnav::estimator::test
