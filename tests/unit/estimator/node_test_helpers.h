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

inline EstimatorOptions testOptions() {
  EstimatorOptions o;
  o.window_s = 1.0;
  return o;
}

}  // namespace meshnav::estimator::test
