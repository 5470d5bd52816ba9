// Replay pacing with an injected clock: no test sleeps. The fake clock jumps to the requested time
// (bounded by max_wait), so the emission wall times are exactly the scheduler's decisions.
#include <gtest/gtest.h>

#include <stdexcept>

#include "transport/replay/replay_scheduler.h"

using meshnav::Duration;
using meshnav::Timestamp;
using namespace meshnav::replay;

namespace {

class FakeClock : public Clock {
 public:
  explicit FakeClock(int64_t now) : now_(now) {}
  int64_t nowUtime() override { return now_ += tick_; }
  void sleepUntil(int64_t wall, int64_t max_wait) override {
    ++sleeps;
    now_ = std::min(wall, now_ + max_wait);
  }
  void advance(int64_t us) { now_ += us; }
  int64_t peek() const { return now_; }
  int sleeps = 0;
  int64_t tick_ = 0;  ///< time that passes at every reading (simulates work)

 private:
  int64_t now_;
};

std::vector<ReplayEvent> eventsAt(const std::vector<int64_t>& us) {
  std::vector<Timestamp> t;
  for (auto u : us) t.push_back(Timestamp{u});
  return mergeTimeline({t});
}

/// Wall time of every emission.
std::vector<int64_t> emissionTimes(ReplayScheduler& s, FakeClock& clock, const std::vector<ReplayEvent>& ev,
                                   ReplayProgress* progress = nullptr) {
  std::vector<int64_t> out;
  auto p = s.run(ev, [&](const ReplayEvent&) { out.push_back(clock.peek()); });
  if (progress) *progress = p;
  return out;
}

constexpr int64_t kStart = 1'700'000'000'000'000;

}  // namespace

TEST(ReplayScheduler, RealTimeRate) {
  FakeClock clock(kStart);
  ReplayOptions o;
  o.rate = 1.0;
  o.progress_period = Duration{0};
  ReplayScheduler s(o, clock);
  const auto times = emissionTimes(s, clock, eventsAt({2'000'000, 2'005'000, 2'500'000, 4'000'000}));
  ASSERT_EQ(times.size(), 4u);
  EXPECT_EQ(times[0], kStart);  // first event at once
  EXPECT_EQ(times[1], kStart + 5'000);
  EXPECT_EQ(times[2], kStart + 500'000);
  EXPECT_EQ(times[3], kStart + 2'000'000);
}

TEST(ReplayScheduler, TenTimesFaster) {
  FakeClock clock(kStart);
  ReplayOptions o;
  o.rate = 10.0;
  o.progress_period = Duration{0};
  ReplayScheduler s(o, clock);
  const auto times = emissionTimes(s, clock, eventsAt({0, 1'000'000, 10'000'000}));
  EXPECT_EQ(times, (std::vector<int64_t>{kStart, kStart + 100'000, kStart + 1'000'000}));
}

TEST(ReplayScheduler, AsFastAsPossibleNeverSleeps) {
  FakeClock clock(kStart);
  ReplayOptions o;
  o.rate = 0.0;
  o.progress_period = Duration{0};
  ReplayScheduler s(o, clock);
  ReplayProgress p;
  const auto times = emissionTimes(s, clock, eventsAt({0, 1'000'000, 100'000'000}), &p);
  EXPECT_EQ(clock.sleeps, 0);
  EXPECT_EQ(times, (std::vector<int64_t>{kStart, kStart, kStart}));
  EXPECT_EQ(p.emitted, 3u);
  EXPECT_FALSE(p.stopped);
}

TEST(ReplayScheduler, LongWaitsAreSlicedSoStopIsSeen) {
  FakeClock clock(kStart);
  ReplayOptions o;
  o.rate = 1.0;
  o.max_sleep_us = 50'000;
  o.progress_period = Duration{0};
  ReplayScheduler s(o, clock);
  emissionTimes(s, clock, eventsAt({0, 1'000'000}));
  EXPECT_EQ(clock.sleeps, 20);  // 1 s in 50 ms slices
}

TEST(ReplayScheduler, SharedT0KeepsTwoReplaysInStep) {
  // Two bridges started at different wall times, same t0: the same data time is played at the
  // same wall time by both.
  const int64_t t0 = kStart + 3'000'000;
  ReplayOptions o;
  o.rate = 2.0;
  o.t0_wall_utime = t0;
  o.progress_period = Duration{0};
  FakeClock imu_clock(kStart), uwb_clock(kStart + 1'234'567);
  ReplayScheduler imu(o, imu_clock), uwb(o, uwb_clock);
  const auto imu_times = emissionTimes(imu, imu_clock, eventsAt({0, 1'000'000, 2'000'000}));
  const auto uwb_times = emissionTimes(uwb, uwb_clock, eventsAt({500'000, 1'000'000}));
  EXPECT_EQ(imu_times, (std::vector<int64_t>{t0, t0 + 500'000, t0 + 1'000'000}));
  EXPECT_EQ(uwb_times, (std::vector<int64_t>{t0 + 250'000, t0 + 500'000}));
  EXPECT_EQ(imu.dueWallUtime(Timestamp{1'000'000}), uwb.dueWallUtime(Timestamp{1'000'000}));
}

TEST(ReplayScheduler, ExplicitDataT0) {
  FakeClock clock(kStart);
  ReplayOptions o;
  o.rate = 1.0;
  o.t0_wall_utime = kStart + 1'000'000;
  o.data_t0 = Timestamp{1'693'508'300'000'000};  // Unix-stamped recording
  o.progress_period = Duration{0};
  ReplayScheduler s(o, clock);
  const auto times = emissionTimes(s, clock, eventsAt({1'693'508'300'500'000, 1'693'508'301'000'000}));
  EXPECT_EQ(times, (std::vector<int64_t>{kStart + 1'500'000, kStart + 2'000'000}));
}

TEST(ReplayScheduler, AbsurdFirstWaitThrows) {
  FakeClock clock(kStart);
  ReplayOptions o;
  o.rate = 1.0;
  o.t0_wall_utime = kStart;  // data_t0 defaults to 0, but the data is stamped in Unix time
  ReplayScheduler s(o, clock);
  EXPECT_THROW(s.run(eventsAt({1'693'508'300'000'000}), [](const ReplayEvent&) {}), std::invalid_argument);
}

TEST(ReplayScheduler, NegativeRateThrows) {
  FakeClock clock(kStart);
  ReplayOptions o;
  o.rate = -1.0;
  EXPECT_THROW(ReplayScheduler(o, clock), std::invalid_argument);
}

TEST(ReplayScheduler, LateStartCatchesUpAndReportsLag) {
  // t0 already 1 s in the past: the events due before now go out at once, the rest on time.
  FakeClock clock(kStart);
  ReplayOptions o;
  o.rate = 1.0;
  o.t0_wall_utime = kStart - 1'000'000;
  o.progress_period = Duration{0};
  ReplayScheduler s(o, clock);
  ReplayProgress p;
  const auto times = emissionTimes(s, clock, eventsAt({0, 500'000, 2'000'000}), &p);
  EXPECT_EQ(times, (std::vector<int64_t>{kStart, kStart, kStart + 1'000'000}));
  EXPECT_EQ(p.max_lag_us, 1'000'000);
}

TEST(ReplayScheduler, StopPredicateEndsEarly) {
  FakeClock clock(kStart);
  ReplayOptions o;
  o.rate = 1.0;
  o.progress_period = Duration{0};
  ReplayScheduler s(o, clock);
  int emitted = 0;
  const auto p = s.run(eventsAt({0, 100'000, 200'000, 300'000}), [&](const ReplayEvent&) { ++emitted; },
                       [&] { return emitted >= 2; });
  EXPECT_EQ(emitted, 2);
  EXPECT_TRUE(p.stopped);
  EXPECT_EQ(p.emitted, 2u);
}

TEST(ReplayScheduler, ProgressLines) {
  FakeClock clock(kStart);
  ReplayOptions o;
  o.rate = 1.0;
  o.progress_period = Duration::fromSec(1.0);
  ReplayScheduler s(o, clock);
  std::vector<std::string> lines;
  s.setProgressSink([&](const std::string& l) { lines.push_back(l); });
  std::vector<int64_t> t;
  for (int i = 0; i <= 40; ++i) t.push_back(i * 100'000);  // 4 s at 10 Hz
  s.run(eventsAt(t), [](const ReplayEvent&) {});
  ASSERT_EQ(lines.size(), 4u);  // at 1, 2, 3, 4 s
  EXPECT_NE(lines[0].find("replay 1.0/4.0 s"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("11/41 msgs"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("1x"), std::string::npos) << lines[0];
}

TEST(ReplayScheduler, EmptyTimeline) {
  FakeClock clock(kStart);
  ReplayScheduler s(ReplayOptions{}, clock);
  const auto p = s.run({}, [](const ReplayEvent&) { FAIL(); });
  EXPECT_EQ(p.total, 0u);
}
