#include <gtest/gtest.h>

#include <map>

#include "sim/paper_scenario.h"
#include "sim/tdma_schedule.h"

using namespace meshnav::sim;

TEST(SimTdmaSchedule, SlotsAreTenMillisecondsApartAndCycleOverAllOrderedPairs) {
  const TdmaSchedule schedule(PaperScenario::paper().uwbDeviceIds(), 0.01, 0.0042);
  EXPECT_EQ(schedule.devices().size(), 11u);
  EXPECT_EQ(schedule.devices().front(), 100);
  EXPECT_EQ(schedule.devices().back(), 110);
  EXPECT_EQ(schedule.slotsPerCycle(), 110);
  EXPECT_NEAR(schedule.cycleDuration(), 1.1, 1e-12);

  const double T = 110.0;
  const auto slots = schedule.slotsUntil(T);
  std::map<std::pair<int, int>, int> per_pair;
  for (size_t k = 0; k < slots.size(); ++k) {
    EXPECT_NE(slots[k].initiator, slots[k].responder);
    if (k > 0) {
      EXPECT_NEAR(slots[k].t_s - slots[k - 1].t_s, 0.01, 1e-9);
    }
    ++per_pair[{slots[k].initiator, slots[k].responder}];
  }
  EXPECT_NEAR(slots.front().t_s, 0.0042, 1e-12);
  EXPECT_EQ(per_pair.size(), 110u);  // every ordered pair
  for (const auto& [pair, n] : per_pair) EXPECT_NEAR(n / T, 1.0 / 1.1, 0.01);  // ≈ 0.91 Hz

  // Within a cycle: device k initiates 10 consecutive slots to the others in id order.
  EXPECT_EQ(slots[0].initiator, 100);
  EXPECT_EQ(slots[0].responder, 101);
  EXPECT_EQ(slots[9].responder, 110);
  EXPECT_EQ(slots[10].initiator, 101);
  EXPECT_EQ(slots[10].responder, 100);
  EXPECT_EQ(slots[11].responder, 102);
  EXPECT_EQ(slots[109].initiator, 110);
  EXPECT_EQ(slots[109].responder, 109);
  EXPECT_EQ(slots[110].initiator, 100);
}

TEST(SimTdmaSchedule, RejectsDegenerateDeviceLists) {
  EXPECT_THROW(TdmaSchedule({100}), std::invalid_argument);
  EXPECT_THROW(TdmaSchedule({100, 100}), std::invalid_argument);
  EXPECT_THROW(TdmaSchedule({100, 101}, 0.0), std::invalid_argument);
  // Unsorted input is sorted.
  const TdmaSchedule s({105, 100, 101});
  EXPECT_EQ(s.slot(0).initiator, 100);
}
