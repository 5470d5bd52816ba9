/// @file cell_tdma_schedule.cpp
/// @brief CellTdmaSchedule: frames of colour phases, tag and anchor seats.

#include "sim/cell_tdma_schedule.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace meshnav::sim {

void CellTdmaOptions::validate() const {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("CellTdmaOptions: ") + what);
  };
  require(slot_s > 0.0 && slot_s <= 1.0, "slot_s must be in (0, 1] s");
  require(tag_seats >= 0 && tag_slots >= 0 && anchor_seats >= 0 && anchor_slots >= 0 && peer_slots >= 0,
          "seats and slots must be >= 0");
  require(tag_seats * tag_slots + anchor_seats * anchor_slots > 0, "a phase needs at least one slot");
}

std::string CellTdmaOptions::toString() const {
  std::ostringstream s;
  s << "cell TDMA: slot " << slot_s * 1e3 << " ms, " << tag_seats << " tag seats x " << tag_slots << " slots, "
    << anchor_seats << " anchor seats x " << anchor_slots << " slots per cell and phase, " << peer_slots
    << " peer slots per fleet tag and frame";
  return s.str();
}

CellTdmaSchedule::CellTdmaSchedule(int n_colours, const CellTdmaOptions& options, double t0_s, int n_fleet_tags)
    : n_colours_(n_colours), options_(options), t0_s_(t0_s), n_fleet_tags_(n_fleet_tags) {
  if (n_colours < 1) throw std::invalid_argument("CellTdmaSchedule: needs at least one colour");
  if (n_fleet_tags < 0) throw std::invalid_argument("CellTdmaSchedule: n_fleet_tags must be >= 0");
  options_.validate();
}

int CellTdmaSchedule::slotsPerPhase() const {
  return options_.tag_seats * options_.tag_slots + options_.anchor_seats * options_.anchor_slots;
}

CellTdmaSlot CellTdmaSchedule::slot(int64_t s) const {
  const int64_t per_frame = slotsPerFrame();
  const int64_t in_frame = s % per_frame;
  CellTdmaSlot out;
  out.index = s;
  out.t_s = t0_s_ + static_cast<double>(s) * options_.slot_s;
  out.frame = s / per_frame;
  const int64_t cell_part = static_cast<int64_t>(n_colours_) * slotsPerPhase();
  if (in_frame >= cell_part) {  // the peer phase
    out.colour = -1;
    out.phase_slot = static_cast<int>(in_frame - cell_part);
    out.role = CellSlotRole::PeerSeat;
    out.seat = out.phase_slot / options_.peer_slots;
    return out;
  }
  out.colour = static_cast<int>(in_frame / slotsPerPhase());
  out.phase_slot = static_cast<int>(in_frame % slotsPerPhase());
  const int tag_part = options_.tag_seats * options_.tag_slots;
  if (out.phase_slot < tag_part) {
    out.role = CellSlotRole::TagSeat;
    out.seat = out.phase_slot / options_.tag_slots;
  } else {
    out.role = CellSlotRole::AnchorSeat;
    out.seat = (out.phase_slot - tag_part) / options_.anchor_slots;
  }
  return out;
}

int64_t CellTdmaSchedule::slotCountUntil(double t_end_s) const {
  if (t_end_s < t0_s_) return 0;
  return static_cast<int64_t>(std::floor((t_end_s - t0_s_) / options_.slot_s + 1e-9)) + 1;
}

std::string CellTdmaSchedule::toString() const {
  std::ostringstream s;
  s << options_.toString() << "; " << n_colours_ << " phases of " << slotsPerPhase() << " slots, frame "
    << frameDuration() << " s: a seated tag ranges at " << tagRangeRateHz() << " Hz, an anchor at "
    << anchorRangeRateHz() << " Hz";
  if (hasPeerPhase())
    s << "; peer phase of " << peerPhaseSlots() << " slots: a tag ranges to other vehicles' tags at " << peerRangeRateHz()
      << " Hz";
  return s.str();
}

}  // namespace meshnav::sim
