#include <gtest/gtest.h>

#include <stdexcept>

#include "sim/cell_tdma_schedule.h"

using namespace meshnav::sim;

TEST(SimCellTdmaSchedule, DefaultFrameIsNinePhasesOfTwentySlots) {
  const CellTdmaSchedule s(9, CellTdmaOptions{}, 0.0013);
  EXPECT_EQ(s.slotsPerPhase(), 20);
  EXPECT_EQ(s.slotsPerFrame(), 180);
  EXPECT_NEAR(s.frameDuration(), 0.36, 1e-12);
  EXPECT_NEAR(s.tagRangeRateHz(), 4.0 / 0.36, 1e-9);     // 11.1 Hz per seated tag
  EXPECT_NEAR(s.anchorRangeRateHz(), 1.0 / 0.36, 1e-9);  // 2.8 Hz per anchor

  const CellTdmaSlot first = s.slot(0);
  EXPECT_EQ(first.colour, 0);
  EXPECT_EQ(first.phase_slot, 0);
  EXPECT_EQ(first.role, CellSlotRole::TagSeat);
  EXPECT_EQ(first.seat, 0);
  EXPECT_NEAR(first.t_s, 0.0013, 1e-12);
  EXPECT_EQ(s.slot(3).seat, 0);  // a tag's four slots in a row
  EXPECT_EQ(s.slot(4).seat, 1);
  EXPECT_EQ(s.slot(15).role, CellSlotRole::TagSeat);
  EXPECT_EQ(s.slot(15).seat, 3);
  EXPECT_EQ(s.slot(16).role, CellSlotRole::AnchorSeat);
  EXPECT_EQ(s.slot(16).seat, 0);
  EXPECT_EQ(s.slot(19).seat, 3);
  EXPECT_EQ(s.slot(20).colour, 1);
  EXPECT_EQ(s.slot(20).phase_slot, 0);
  EXPECT_EQ(s.slot(179).colour, 8);
  EXPECT_EQ(s.slot(179).frame, 0);
  const CellTdmaSlot next = s.slot(180 + 37);
  EXPECT_EQ(next.frame, 1);
  EXPECT_EQ(next.colour, 1);
  EXPECT_EQ(next.phase_slot, 17);
  EXPECT_EQ(next.role, CellSlotRole::AnchorSeat);
  EXPECT_EQ(next.seat, 1);
  EXPECT_NEAR(next.t_s, 0.0013 + 217 * 0.002, 1e-12);
  EXPECT_EQ(s.slotCountUntil(0.0013 + 1.0), 501);
  EXPECT_EQ(s.slotCountUntil(0.0), 0);
}

TEST(SimCellTdmaSchedule, OtherSeatsAndBadOptions) {
  CellTdmaOptions o;
  o.tag_seats = 2;
  o.tag_slots = 3;
  o.anchor_seats = 4;
  o.anchor_slots = 2;
  o.slot_s = 0.005;
  const CellTdmaSchedule s(4, o);
  EXPECT_EQ(s.slotsPerPhase(), 14);
  EXPECT_NEAR(s.frameDuration(), 4 * 14 * 0.005, 1e-12);
  EXPECT_EQ(s.slot(6).role, CellSlotRole::AnchorSeat);
  EXPECT_EQ(s.slot(7).seat, 0);
  EXPECT_EQ(s.slot(8).seat, 1);
  EXPECT_THROW(CellTdmaSchedule(0, o), std::invalid_argument);
  o.slot_s = 0.0;
  EXPECT_THROW(CellTdmaSchedule(4, o), std::invalid_argument);
  CellTdmaOptions empty;
  empty.tag_seats = empty.anchor_seats = 0;
  EXPECT_THROW(CellTdmaSchedule(4, empty), std::invalid_argument);
}

TEST(SimCellTdmaSchedule, APeerPhaseEndsEachFrameWithSlotsForEveryFleetTag) {
  // Ten fleet tags, one peer slot each: 180 + 10 slots = 0.38 s.
  const CellTdmaSchedule s(9, CellTdmaOptions{}, 0.0, 10);
  EXPECT_TRUE(s.hasPeerPhase());
  EXPECT_EQ(s.peerPhaseSlots(), 10);
  EXPECT_EQ(s.slotsPerFrame(), 190);
  EXPECT_NEAR(s.frameDuration(), 0.38, 1e-12);
  EXPECT_NEAR(s.tagRangeRateHz(), 4.0 / 0.38, 1e-9);
  EXPECT_NEAR(s.peerRangeRateHz(), 1.0 / 0.38, 1e-9);
  EXPECT_EQ(s.slot(179).role, CellSlotRole::AnchorSeat);
  EXPECT_EQ(s.slot(179).colour, 8);
  for (int k = 0; k < 10; ++k) {
    const CellTdmaSlot p = s.slot(180 + k);
    EXPECT_EQ(p.role, CellSlotRole::PeerSeat);
    EXPECT_EQ(p.colour, -1);
    EXPECT_EQ(p.seat, k);
    EXPECT_EQ(p.frame, 0);
  }
  const CellTdmaSlot next = s.slot(190);
  EXPECT_EQ(next.frame, 1);
  EXPECT_EQ(next.colour, 0);
  EXPECT_EQ(next.role, CellSlotRole::TagSeat);
  // Two peer slots per tag: seat = slot / 2; no peer phase with m_p = 0 or no tags.
  CellTdmaOptions two;
  two.peer_slots = 2;
  const CellTdmaSchedule s2(9, two, 0.0, 3);
  EXPECT_EQ(s2.slotsPerFrame(), 186);
  EXPECT_EQ(s2.slot(181).seat, 0);
  EXPECT_EQ(s2.slot(182).seat, 1);
  EXPECT_EQ(s2.slot(185).seat, 2);
  CellTdmaOptions none;
  none.peer_slots = 0;
  EXPECT_FALSE(CellTdmaSchedule(9, none, 0.0, 10).hasPeerPhase());
  EXPECT_EQ(CellTdmaSchedule(9, none, 0.0, 10).slotsPerFrame(), 180);
  EXPECT_EQ(CellTdmaSchedule(9, CellTdmaOptions{}).peerRangeRateHz(), 0.0);
  EXPECT_THROW(CellTdmaSchedule(9, CellTdmaOptions{}, 0.0, -1), std::invalid_argument);
  none.peer_slots = -1;
  EXPECT_THROW(CellTdmaSchedule(9, none, 0.0, 10), std::invalid_argument);
}
