#pragma once
/// @file cell_tdma_schedule.h
/// @brief TDMA with cells and slot reuse (docs/scenarios.md, "A hundred anchors in TDMA cells").
///
/// A **frame** is C **phases**, one per colour of the `CellGrid` (9 for reuse distance 3); in phase
/// c every cell of colour c is active at once (their 3 × 3 neighbourhoods share no cell), the others
/// are silent. A phase has P = T·m_t + A·m_a slots of Δt:
///  - T **tag seats** of m_t slots each: the tags inside the cell at the phase's first slot, in id
///    order, take the seats (a tag beyond T waits for a later frame: "seat overflow"); a seated tag
///    initiates m_t SDS-TWR ranges, each to the next device of its round robin over the anchors of
///    the cell's neighbourhood (and the other vehicles' tags in it);
///  - A **anchor seats** of m_a slots: the cell's anchors in id order; each initiates m_a ranges to
///    the next anchor of its round robin over the neighbourhood's other anchors (the anchor mesh).
/// Global slot s ↦ frame ⌊s / (C·P)⌋, phase c = ⌊(s mod C·P) / P⌋, slot q = s mod P of the phase;
/// t(s) = t₀ + s·Δt. A seated tag ranges at m_t / (C·P·Δt): with the defaults (Δt = 2 ms, T = 4,
/// m_t = 4, A = 4, m_a = 1, C = 9) a frame is 180 slots = 0.36 s and a tag ranges at 11.1 Hz, a
/// vehicle with two tags at 22.2 Hz; an anchor initiates at 2.8 Hz.

#include <cstdint>
#include <string>

namespace meshnav::sim {

struct CellTdmaOptions {
  double slot_s = 0.002;  ///< Δt, one SDS-TWR exchange with guard time [s]
  int tag_seats = 4;      ///< T: tags served per cell and phase
  int tag_slots = 4;      ///< m_t: ranges per seated tag and phase
  int anchor_seats = 4;   ///< A: ≥ the anchors of the fullest cell
  int anchor_slots = 1;   ///< m_a: ranges per anchor and phase
  /// Throws std::invalid_argument naming the bad field.
  void validate() const;
  std::string toString() const;
};

enum class CellSlotRole { TagSeat, AnchorSeat };

struct CellTdmaSlot {
  int64_t index = 0;   ///< global slot s
  double t_s = 0.0;    ///< slot time [s]
  int64_t frame = 0;   ///< ⌊s / (C·P)⌋
  int colour = 0;      ///< the phase: the active cells' colour
  int phase_slot = 0;  ///< q ∈ [0, P)
  CellSlotRole role = CellSlotRole::TagSeat;
  int seat = 0;        ///< tag seat ∈ [0, T) or anchor seat ∈ [0, A)
};

class CellTdmaSchedule {
 public:
  /// Throws std::invalid_argument for n_colours < 1 or invalid options.
  CellTdmaSchedule(int n_colours, const CellTdmaOptions& options, double t0_s = 0.0);

  int slotsPerPhase() const;
  int64_t slotsPerFrame() const { return static_cast<int64_t>(n_colours_) * slotsPerPhase(); }
  double frameDuration() const { return static_cast<double>(slotsPerFrame()) * options_.slot_s; }
  /// Ranges per second initiated by a seated tag [Hz].
  double tagRangeRateHz() const { return options_.tag_slots / frameDuration(); }
  /// Ranges per second initiated by an anchor [Hz].
  double anchorRangeRateHz() const { return options_.anchor_slots / frameDuration(); }
  int colourCount() const { return n_colours_; }
  const CellTdmaOptions& options() const { return options_; }
  CellTdmaSlot slot(int64_t s) const;
  /// Number of slots with t₀ ≤ t(s) ≤ t_end_s (1e-9 slots of tolerance).
  int64_t slotCountUntil(double t_end_s) const;
  std::string toString() const;

 private:
  int n_colours_;
  CellTdmaOptions options_;
  double t0_s_;
};

}  // namespace meshnav::sim
