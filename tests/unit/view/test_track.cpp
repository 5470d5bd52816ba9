#include "view/track.h"

#include <gtest/gtest.h>

using meshnav::view::JsonWriter;
using meshnav::view::Track;

namespace {
std::string written(const Track& t, int64_t epoch, size_t since) {
  JsonWriter w;
  t.write(w, epoch, since);
  return w.str();
}
}  // namespace

TEST(Track, SendsOnlyTheRowsAfterTheClientsWithinAnEpoch) {
  Track t(2, 10, Track::Overflow::Thin);
  t.append({0, 1});
  t.append({1, 2});
  t.append({2, 3});
  EXPECT_EQ(written(t, 0, 2), R"({"epoch":0,"start":2,"rows":[[2,3]]})");
  EXPECT_EQ(written(t, 0, 3), R"({"epoch":0,"start":3,"rows":[]})");
  // A client of another epoch, or claiming more rows than there are, gets everything.
  EXPECT_EQ(written(t, -1, 0), R"({"epoch":0,"start":0,"rows":[[0,1],[1,2],[2,3]]})");
  EXPECT_EQ(written(t, 0, 7), R"({"epoch":0,"start":0,"rows":[[0,1],[1,2],[2,3]]})");
  EXPECT_THROW(t.append({1}), std::invalid_argument);
}

TEST(Track, ThinningKeepsTheWholeSpanAndStartsANewEpoch) {
  Track t(1, 4, Track::Overflow::Thin);
  for (int i = 0; i < 5; ++i) t.append({static_cast<double>(i)});
  // Full at 4 rows [0 1 2 3]: thinned to [0 2 3] (the newest kept), then 4 appended.
  ASSERT_EQ(t.epoch(), 1);
  ASSERT_EQ(t.size(), 4u);
  EXPECT_EQ(t.at(0, 0), 0);
  EXPECT_EQ(t.at(1, 0), 2);
  EXPECT_EQ(t.at(2, 0), 3);
  EXPECT_EQ(t.at(3, 0), 4);
}

TEST(Track, DropOldestKeepsTheNewestHalf) {
  Track t(1, 4, Track::Overflow::DropOldest);
  for (int i = 0; i < 5; ++i) t.append({static_cast<double>(i)});
  ASSERT_EQ(t.epoch(), 1);
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t.at(0, 0), 2);
  EXPECT_EQ(t.at(2, 0), 4);
}
