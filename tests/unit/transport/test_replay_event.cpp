// Merging several sample streams into one deterministic time line.
#include <gtest/gtest.h>

#include "transport/replay/replay_event.h"

using meshnav::Timestamp;
using namespace meshnav::replay;

TEST(ReplayTimeline, SortedByTimeStableAcrossStreams) {
  const std::vector<std::vector<Timestamp>> streams = {
      {Timestamp{0}, Timestamp{10}, Timestamp{20}},  // e.g. IMU
      {Timestamp{10}, Timestamp{15}},                // e.g. BARO
      {},                                            // an empty stream
      {Timestamp{5}, Timestamp{10}}};
  const auto ev = mergeTimeline(streams);
  ASSERT_EQ(ev.size(), 7u);
  const std::vector<std::pair<int, size_t>> expected = {{0, 0}, {3, 0}, {0, 1}, {1, 0}, {3, 1}, {1, 1}, {0, 2}};
  for (size_t i = 0; i < ev.size(); ++i) {
    EXPECT_EQ(ev[i].stream, expected[i].first) << i;
    EXPECT_EQ(ev[i].index, expected[i].second) << i;
    if (i) {
      EXPECT_LE(ev[i - 1].t, ev[i].t);
    }
  }
}

TEST(ReplayTimeline, UnsortedStreamIsSorted) {
  const auto ev = mergeTimeline({{Timestamp{30}, Timestamp{10}, Timestamp{20}}});
  ASSERT_EQ(ev.size(), 3u);
  EXPECT_EQ(ev[0].index, 1u);
  EXPECT_EQ(ev[1].index, 2u);
  EXPECT_EQ(ev[2].index, 0u);
}

TEST(ReplayTimeline, Empty) { EXPECT_TRUE(mergeTimeline({}).empty()); }
