#pragma once
/// @file bias_state.h
/// @brief Estimated constant range biases γ of one instance towards its peers (the value of the
/// tag and anchor kinds' bias states).

#include <Eigen/Core>
#include <vector>

#include "common/types.h"

namespace meshnav::estimator {

/// Estimated constant range biases γ (z = βd + γ + ν) of one instance towards its peers: state i
/// is γ(owner, peers[i]) [m]. Owners: a tag (towards exactly known anchors; its whole error state)
/// or an estimated anchor (towards the references of its calibration: tags, known and earlier
/// calibrated anchors; error-state rows 3.. after its position).
struct BiasState {
  std::vector<SensorId> peers;
  Eigen::VectorXd gamma_m;
  /// Index of `peer` in the state, or −1.
  int index(SensorId peer) const {
    for (size_t i = 0; i < peers.size(); ++i)
      if (peers[i] == peer) return static_cast<int>(i);
    return -1;
  }
};

}  // namespace meshnav::estimator
