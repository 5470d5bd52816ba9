#pragma once
/// @file nominal_state.h
/// @brief Nominal (mean) values of every instance with state, addressed by instance id.

#include <Eigen/Core>
#include <map>
#include <vector>

#include "common/time.h"
#include "common/types.h"
#include "estimator/core/imu_state.h"
#include "estimator/core/state_layout.h"

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

struct NominalState {
  Timestamp t;                                       ///< time the state is valid at
  SensorId imu_id = 1;
  ImuState imu;
  std::map<SensorId, double> baro_bias_m;            ///< barometer height bias b_P [m]
  std::map<SensorId, double> height_bias_m;          ///< downward rangefinder bias b_H [m]
  std::map<SensorId, Eigen::Vector3d> anchor_p_AinG; ///< estimated anchors' positions [m]
  std::map<SensorId, BiasState> tag_biases;        ///< estimated tag–anchor biases γ [m]
  std::map<SensorId, BiasState> anchor_biases;     ///< estimated anchors' biases γ towards peers [m]

  /// Applies the correction `dx` (size b.dim) of one instance's block.
  template <typename Derived>
  void boxplusBlock(const StateBlock& b, const Eigen::MatrixBase<Derived>& dx) {
    switch (b.kind) {
      case InstanceKind::Imu: imu.boxplus(dx.template head<ImuErr::kDim>()); break;
      case InstanceKind::Baro: baro_bias_m.at(b.id) += dx(0); break;
      case InstanceKind::Height: height_bias_m.at(b.id) += dx(0); break;
      case InstanceKind::Anchor:
        anchor_p_AinG.at(b.id) += dx.template head<3>();
        if (b.dim > 3) anchor_biases.at(b.id).gamma_m += dx.segment(3, b.dim - 3);
        break;
      case InstanceKind::Tag: tag_biases.at(b.id).gamma_m += dx.head(b.dim); break;
    }
  }
  /// Forgets the nominal values of instance `id` (baro or height bias, anchor position and biases, tag biases).
  void erase(SensorId id) {
    baro_bias_m.erase(id);
    height_bias_m.erase(id);
    anchor_p_AinG.erase(id);
    tag_biases.erase(id);
    anchor_biases.erase(id);
  }

  /// Applies a stacked error-state correction laid out as `layout`.
  void boxplus(const StateLayout& layout, const Eigen::VectorXd& dx) {
    for (const StateBlock& b : layout.blocks()) boxplusBlock(b, dx.segment(b.offset, b.dim));
  }
};

}  // namespace meshnav::estimator
