#include "sim/tdma_schedule.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace meshnav::sim {

TdmaSchedule::TdmaSchedule(std::vector<SensorId> device_ids, double slot_s, double t0_s)
    : ids_(std::move(device_ids)), n_(static_cast<int>(ids_.size())), slot_s_(slot_s), t0_s_(t0_s) {
  std::sort(ids_.begin(), ids_.end());
  if (n_ < 2) throw std::invalid_argument("TdmaSchedule: needs at least two devices");
  if (std::adjacent_find(ids_.begin(), ids_.end()) != ids_.end())
    throw std::invalid_argument("TdmaSchedule: duplicate device id");
  if (!(slot_s_ > 0.0)) throw std::invalid_argument("TdmaSchedule: slot_s must be > 0");
}

TdmaSlot TdmaSchedule::slot(int64_t s) const {
  const int64_t in_cycle = s % slotsPerCycle();
  const int k = static_cast<int>(in_cycle / (n_ - 1));
  const int j = static_cast<int>(in_cycle % (n_ - 1));
  TdmaSlot out;
  out.index = s;
  out.t_s = t0_s_ + static_cast<double>(s) * slot_s_;
  out.initiator = ids_[k];
  out.responder = ids_[j < k ? j : j + 1];  // skip the initiator itself
  return out;
}

int64_t TdmaSchedule::slotCountUntil(double t_end_s) const {
  if (t_end_s < t0_s_) return 0;
  return static_cast<int64_t>(std::floor((t_end_s - t0_s_) / slot_s_ + 1e-9)) + 1;
}

std::vector<TdmaSlot> TdmaSchedule::slotsUntil(double t_end_s) const {
  std::vector<TdmaSlot> out;
  const int64_t n = slotCountUntil(t_end_s);
  out.reserve(static_cast<size_t>(n));
  for (int64_t s = 0; s < n; ++s) out.push_back(slot(s));
  return out;
}

}  // namespace meshnav::sim
