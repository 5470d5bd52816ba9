#pragma once
/// @file state_layout.h
/// @brief Named blocks of the stacked error state: one block per instance with state, in the
/// order IMU, baro, anchors (insertion order). Offsets are derived, never written by hand.

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/types.h"
#include "estimator/core/instance_kind.h"

namespace meshnav::estimator {

/// One instance's block in the stacked error state.
struct StateBlock {
  SensorId id = 0;
  InstanceKind kind = kindOf<ImuKind>;
  int offset = 0;  ///< first row/column in the stacked error state
  int dim = 0;     ///< error-state dimension
};

/// Ordered list of state blocks. Adding appends; removing closes the gap.
class StateLayout {
 public:
  /// Appends a block for `id` of dimension `dim` (negative: the kind's default; throws if `id`
  /// already has a block).
  const StateBlock& add(SensorId id, InstanceKind kind, int dim = -1) {
    if (find(id)) throw std::logic_error("StateLayout: instance " + std::to_string(id) + " already has a block");
    const int d = dim < 0 ? errorDim(kind) : dim;
    blocks_.push_back({id, kind, dim_, d});
    dim_ += d;
    return blocks_.back();
  }
  /// Removes the block of `id` and shifts the following ones; returns the removed block.
  std::optional<StateBlock> remove(SensorId id) {
    for (size_t i = 0; i < blocks_.size(); ++i) {
      if (blocks_[i].id != id) continue;
      const StateBlock removed = blocks_[i];
      blocks_.erase(blocks_.begin() + static_cast<long>(i));
      for (size_t j = i; j < blocks_.size(); ++j) blocks_[j].offset -= removed.dim;
      dim_ -= removed.dim;
      return removed;
    }
    return std::nullopt;
  }
  const StateBlock* find(SensorId id) const {
    for (const auto& b : blocks_)
      if (b.id == id) return &b;
    return nullptr;
  }
  const StateBlock& at(SensorId id) const {
    const StateBlock* b = find(id);
    if (!b) throw std::out_of_range("StateLayout: no block for instance " + std::to_string(id));
    return *b;
  }
  const std::vector<StateBlock>& blocks() const { return blocks_; }
  /// Total error-state dimension.
  int dim() const { return dim_; }

 private:
  std::vector<StateBlock> blocks_;
  int dim_ = 0;
};

}  // namespace meshnav::estimator
