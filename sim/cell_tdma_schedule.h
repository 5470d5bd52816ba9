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
/// After the C phases, a **peer phase** (when the fleet has N_T > 0 tags and m_p > 0): m_p slots for
/// each of the fleet's N_T tags in id order, fleet-wide (no reuse: one exchange at a time in the
/// hall); a tag initiates each to the next tag of its round robin over the other vehicles' tags.
/// Tags then range to each other only there (a peer is no longer a device of the cells' round robin).
/// A frame is F = C·P + N_T·m_p slots. Global slot s ↦ frame ⌊s / F⌋; within it, q' = s mod F:
/// phase c = ⌊q' / P⌋ and slot q = q' mod P of the phase for q' < C·P, else peer seat
/// ⌊(q' − C·P) / m_p⌋; t(s) = t₀ + s·Δt. A seated tag ranges to anchors at m_t / (F·Δt), to peers
/// at m_p / (F·Δt): with the defaults (Δt = 2 ms, T = 4, m_t = 4, A = 4, m_a = 1, C = 9, m_p = 1)
/// and 10 fleet tags a frame is 190 slots = 0.38 s, a tag ranges to anchors at 10.5 Hz (a vehicle
/// with two tags at 21.1 Hz) and to peers at 2.6 Hz; an anchor initiates at 2.6 Hz. Without the
/// peer phase (m_p = 0 or no tags) a frame is 180 slots = 0.36 s, 11.1 Hz per tag, peers inside
/// the cells' round robin.

#include <cstdint>
#include <string>

namespace meshnav::sim {

struct CellTdmaOptions {
  double slot_s = 0.002;  ///< Δt, one SDS-TWR exchange with guard time [s]
  int tag_seats = 4;      ///< T: tags served per cell and phase
  int tag_slots = 4;      ///< m_t: ranges per seated tag and phase
  int anchor_seats = 4;   ///< A: ≥ the anchors of the fullest cell
  int anchor_slots = 1;   ///< m_a: ranges per anchor and phase
  /// m_p: slots per fleet tag in the frame's peer phase, tag to tag across the hall (0: no peer
  /// phase, the tags of other vehicles are devices of the cells' round robin).
  int peer_slots = 1;
  /// Throws std::invalid_argument naming the bad field.
  void validate() const;
  std::string toString() const;
};

enum class CellSlotRole { TagSeat, AnchorSeat, PeerSeat };

struct CellTdmaSlot {
  int64_t index = 0;   ///< global slot s
  double t_s = 0.0;    ///< slot time [s]
  int64_t frame = 0;   ///< ⌊s / (C·P)⌋
  int colour = 0;      ///< the phase: the active cells' colour (−1: the peer phase)
  int phase_slot = 0;  ///< q ∈ [0, P)
  CellSlotRole role = CellSlotRole::TagSeat;
  int seat = 0;        ///< tag seat ∈ [0, T), anchor seat ∈ [0, A) or peer seat ∈ [0, N_T) (the fleet's tags in id order)
};

class CellTdmaSchedule {
 public:
  /// `n_fleet_tags`: the tags of every vehicle (N_T, the peer phase's seats; 0: no peer phase).
  /// Throws std::invalid_argument for n_colours < 1, n_fleet_tags < 0 or invalid options.
  CellTdmaSchedule(int n_colours, const CellTdmaOptions& options, double t0_s = 0.0, int n_fleet_tags = 0);

  int slotsPerPhase() const;
  /// Slots of the peer phase, N_T·m_p.
  int peerPhaseSlots() const { return n_fleet_tags_ * options_.peer_slots; }
  bool hasPeerPhase() const { return peerPhaseSlots() > 0; }
  int64_t slotsPerFrame() const { return static_cast<int64_t>(n_colours_) * slotsPerPhase() + peerPhaseSlots(); }
  double frameDuration() const { return static_cast<double>(slotsPerFrame()) * options_.slot_s; }
  /// Ranges per second initiated by a seated tag in the cells [Hz].
  double tagRangeRateHz() const { return options_.tag_slots / frameDuration(); }
  /// Ranges per second a tag initiates in the peer phase [Hz] (0 without one).
  double peerRangeRateHz() const { return hasPeerPhase() ? options_.peer_slots / frameDuration() : 0.0; }
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
  int n_fleet_tags_;
};

}  // namespace meshnav::sim
