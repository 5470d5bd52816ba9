#pragma once
/// @file nominal_state.h
/// @brief Nominal (mean) values of every instance with state, addressed by kind and instance id.

#include <Eigen/Core>
#include <map>
#include <tuple>
#include <type_traits>
#include <variant>

#include "common/time.h"
#include "common/types.h"
#include "estimator/core/imu_state.h"
#include "estimator/core/instance_kind.h"
#include "estimator/core/state_layout.h"

namespace meshnav::estimator {

namespace detail {
/// Storage of one kind: id → value (the body's value is NominalState::imu instead).
template <class K>
using KindValues = std::conditional_t<K::kBody, std::monostate, std::map<SensorId, typename K::Value>>;
template <class List>
struct KindStore;
template <class... K>
struct KindStore<KindList<K...>> {
  using type = std::tuple<KindValues<K>...>;
};
}  // namespace detail

struct NominalState {
  Timestamp t;                                       ///< time the state is valid at
  SensorId imu_id = 1;
  ImuState imu;

  /// The nominal values of every instance of kind K (not the IMU), by id.
  template <class K>
  std::map<SensorId, typename K::Value>& values() {
    static_assert(!K::kBody, "the IMU's value is NominalState::imu");
    return std::get<detail::kindIndex<K>(InstanceKinds{})>(store_);
  }
  template <class K>
  const std::map<SensorId, typename K::Value>& values() const {
    static_assert(!K::kBody, "the IMU's value is NominalState::imu");
    return std::get<detail::kindIndex<K>(InstanceKinds{})>(store_);
  }

  /// Applies the correction `dx` (size b.dim) of one instance's block.
  void boxplusBlock(const StateBlock& b, const Eigen::Ref<const Eigen::VectorXd>& dx) {
    forEachKind([&]<class K>() {
      if (kindOf<K> != b.kind) return;
      if constexpr (K::kBody)
        K::boxplus(imu, dx);
      else
        K::boxplus(values<K>().at(b.id), dx);
    });
  }
  /// Forgets the nominal values of instance `id` (any kind but the IMU).
  void erase(SensorId id) {
    forEachKind([&]<class K>() {
      if constexpr (!K::kBody) values<K>().erase(id);
    });
  }

  /// Applies a stacked error-state correction laid out as `layout`.
  void boxplus(const StateLayout& layout, const Eigen::VectorXd& dx) {
    for (const StateBlock& b : layout.blocks()) boxplusBlock(b, dx.segment(b.offset, b.dim));
  }

 private:
  typename detail::KindStore<InstanceKinds>::type store_;
};

}  // namespace meshnav::estimator
