#pragma once
/// @file instance_kind.h
/// @brief Kinds of sensor instances (paper §III-A): each has a unique id and a state block size.

#include <string>

namespace meshnav::estimator {

/// Type of a sensor instance. Only instances with an error state appear in the filter's layout:
/// the IMU (15), a barometer (its bias, 1), a downward rangefinder (its bias, 1), estimated anchors
/// (position, 3, followed by one γ per estimated pair bias towards its peers) and tags whose
/// constant biases γ towards exactly known anchors are estimated (one state per such pair). Tag and
/// anchor dimensions are given when the block is added. Exactly known anchors are instances without
/// state.
enum class InstanceKind { Imu, Baro, Tag, Anchor, Height };

/// Default error-state dimension of an instance kind (Tag: variable, given at insertion; Anchor: 3
/// without γ states).
constexpr int errorDim(InstanceKind k) {
  switch (k) {
    case InstanceKind::Imu: return 15;
    case InstanceKind::Baro: return 1;
    case InstanceKind::Height: return 1;
    case InstanceKind::Anchor: return 3;
    case InstanceKind::Tag: return 0;
  }
  return 0;
}

/// "imu", "baro", "tag", "anchor", "height" (as in EstimatorStatus).
inline std::string kindName(InstanceKind k) {
  switch (k) {
    case InstanceKind::Imu: return "imu";
    case InstanceKind::Baro: return "baro";
    case InstanceKind::Tag: return "tag";
    case InstanceKind::Anchor: return "anchor";
    case InstanceKind::Height: return "height";
  }
  return "?";
}

}  // namespace meshnav::estimator
