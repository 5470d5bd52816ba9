#pragma once
/// @file tdma_schedule.h
/// @brief Meshed TDMA of the paper (§III-B): the N devices, sorted by id, take turns as initiator;
/// initiator k ranges (SDS-TWR) to each of the other N − 1 devices in id order, one slot of Δt each.
///
/// Global slot s ↦ cycle c = ⌊s / (N(N−1))⌋, initiator k = ⌊(s mod N(N−1)) / (N−1)⌋, responder
/// j-th other device, j = s mod (N−1);  t(s) = t₀ + s·Δt.  One cycle lasts N(N−1)Δt (1.1 s for
/// N = 11, Δt = 10 ms), so every ordered pair is ranged at ≈ 0.91 Hz and every unordered pair at ≈ 1.8 Hz.

#include <cstdint>
#include <vector>

#include "common/types.h"

namespace meshnav::sim {

struct TdmaSlot {
  int64_t index = 0;        ///< global slot index s
  double t_s = 0.0;         ///< slot time [s]
  SensorId initiator = 0;   ///< UWB_ID1
  SensorId responder = 0;   ///< UWB_ID2
};

class TdmaSchedule {
 public:
  /// `device_ids` are sorted ascending internally; needs at least two devices.
  TdmaSchedule(std::vector<SensorId> device_ids, double slot_s = 0.01, double t0_s = 0.0);

  int slotsPerCycle() const { return n_ * (n_ - 1); }
  double cycleDuration() const { return slotsPerCycle() * slot_s_; }
  double slotDuration() const { return slot_s_; }
  const std::vector<SensorId>& devices() const { return ids_; }
  /// The slot with global index `s` (s ≥ 0).
  TdmaSlot slot(int64_t s) const;
  /// Number of slots with t₀ ≤ t(s) ≤ t_end_s (with 1e-9 slots of tolerance on the last).
  int64_t slotCountUntil(double t_end_s) const;
  /// Every slot with t₀ ≤ t(s) ≤ t_end_s, in time order.
  std::vector<TdmaSlot> slotsUntil(double t_end_s) const;

 private:
  std::vector<SensorId> ids_;
  int n_;
  double slot_s_;
  double t0_s_;
};

}  // namespace meshnav::sim
