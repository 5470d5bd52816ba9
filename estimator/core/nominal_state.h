#pragma once
/// @file nominal_state.h
/// @brief Nominal (mean) values of every instance with state, addressed by kind and instance id.

#include <Eigen/Core>
#include <algorithm>
#include <map>
#include <stdexcept>
#include <string>
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

  /// δx = this ⊟ `ref` stacked as `layout` (both hold every instance of the layout with the same
  /// states; throws std::out_of_range or std::invalid_argument otherwise).
  Eigen::VectorXd boxminus(const NominalState& ref, const StateLayout& layout) const {
    Eigen::VectorXd dx(layout.dim());
    for (const StateBlock& b : layout.blocks())
      forEachKind([&]<class K>() {
        if (kindOf<K> != b.kind) return;
        Eigen::VectorXd d;
        if constexpr (K::kBody)
          d = K::boxminus(imu, ref.imu);
        else
          d = K::boxminus(values<K>().at(b.id), ref.values<K>().at(b.id));
        if (d.size() != b.dim)
          throw std::invalid_argument("NominalState::boxminus: instance " + std::to_string(b.id) + " has " +
                                      std::to_string(d.size()) + " states, its block " + std::to_string(b.dim));
        std::copy(d.data(), d.data() + d.size(), dx.data() + b.offset);
      });
    return dx;
  }

  /// Applies a stacked error-state correction laid out as `layout`.
  void boxplus(const StateLayout& layout, const Eigen::VectorXd& dx) {
    for (const StateBlock& b : layout.blocks()) boxplusBlock(b, dx.segment(b.offset, b.dim));
  }

 private:
  typename detail::KindStore<InstanceKinds>::type store_;
};

}  // namespace meshnav::estimator
