#pragma once
/// @file instance_kind.h
/// @brief The registry of instance kinds with state (paper §III-A): the one list that the fusion
/// strategies, NominalState, the status and the node's recovery iterate over. A new kind is a
/// traits struct in its sensor's folder (estimator/core/kind_traits.h says what it holds) plus
/// its include and its name in `InstanceKinds` below (docs/contributing.md, "A new sensor kind").
///
/// Only instances with an error state appear in the filter's layout: the IMU (15), a barometer
/// (its bias, 1), a downward rangefinder (its bias, 1), estimated anchors (position, 3, followed
/// by one γ per estimated pair bias towards its peers) and tags whose constant biases γ towards
/// exactly known anchors are estimated (one state per such pair) and the UWB clock's offset against
/// the IMU (1). Exactly known anchors are instances without state.

#include <array>
#include <string>

#include "estimator/baro/baro_bias_kind.h"
#include "estimator/core/kind_traits.h"
#include "estimator/height/height_bias_kind.h"
#include "estimator/imu/imu_kind.h"
#include "estimator/uwb/anchor_kind.h"
#include "estimator/uwb/clock_offset_kind.h"
#include "estimator/uwb/tag_bias_kind.h"

namespace meshnav::estimator {

/// THE registration: every kind with state, the IMU (the body) first. The order is the order in
/// which a recovery re-adds the instances.
using InstanceKinds = KindList<ImuKind, BaroBiasKind, HeightBiasKind, AnchorKind, TagBiasKind, ClockOffsetKind>;

/// Type of a sensor instance: its kind's position in `InstanceKinds` (kindOf<K>).
enum class InstanceKind : int {};

/// The InstanceKind of kind `K`.
template <class K>
inline constexpr InstanceKind kindOf = InstanceKind{detail::kindIndex<K>(InstanceKinds{})};

inline constexpr int kKindCount = InstanceKinds::kCount;

/// Calls `f.template operator()<K>()` for every registered kind K, in registry order.
template <class F>
void forEachKind(F&& f) {
  detail::forEach(InstanceKinds{}, f);
}

/// Default error-state dimension of a kind (0: variable, given at insertion).
inline int errorDim(InstanceKind k) {
  int d = 0;
  forEachKind([&]<class K>() {
    if (kindOf<K> == k) d = K::kDim;
  });
  return d;
}

/// The kind's name as in EstimatorStatus ("imu", "baro", "height", "anchor", "tag", "uwb_clock").
inline std::string kindName(InstanceKind k) {
  std::string name = "?";
  forEachKind([&]<class K>() {
    if (kindOf<K> == k) name = K::kName;
  });
  return name;
}

/// Random walk σ [unit/√s] of each kind's error states (K::randomWalk), indexed by kind.
struct KindRandomWalks {
  std::array<double, kKindCount> sigma_per_sqrt_s{};
  double of(InstanceKind k) const { return sigma_per_sqrt_s[static_cast<size_t>(k)]; }
  template <class K>
  KindRandomWalks& set(double sigma) {
    sigma_per_sqrt_s[static_cast<size_t>(kindOf<K>)] = sigma;
    return *this;
  }
  /// Every kind's K::randomWalk(o).
  static KindRandomWalks fromOptions(const EstimatorOptions& o) {
    KindRandomWalks w;
    forEachKind([&]<class K>() { w.set<K>(K::randomWalk(o)); });
    return w;
  }
};

}  // namespace meshnav::estimator
