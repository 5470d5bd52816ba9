// Clock offset from request/reply exchanges (common/clock_offset.h): injected offsets of +40 ms and
// -25 ms (the two skewed anchor hosts of the multi-host test) through random one-way delays of
// 20 ± 10 ms, as tc netem gives them.
#include <gtest/gtest.h>

#include <random>

#include "common/clock_offset.h"

using namespace meshnav;

namespace {

/// One exchange between a client whose clock reads true + `client_offset_us` and the reference
/// (true time), with one-way delays `up`, `down` and `turnaround` at the reference [µs].
ClockExchange exchange(int64_t t_true, int64_t client_offset_us, int64_t up, int64_t down, int64_t turnaround = 50) {
  ClockExchange e;
  e.t1 = t_true + client_offset_us;
  e.t2 = t_true + up;
  e.t3 = e.t2 + turnaround;
  e.t4 = e.t3 + down + client_offset_us;
  return e;
}

}  // namespace

TEST(ClockOffset, SymmetricDelaysGiveTheOffsetExactly) {
  for (int64_t c : {40'000, -25'000, 0}) {
    const auto e = exchange(1'700'000'000'000'000, c, 20'000, 20'000);
    EXPECT_EQ(e.offset(), -c);
    EXPECT_EQ(e.roundTrip(), 40'000);
  }
}

TEST(ClockOffset, InjectedOffsetsThroughJitteryDelaysAreRecovered) {
  std::mt19937 rng(12);
  std::uniform_int_distribution<int64_t> delay(10'000, 30'000);  // 20 ± 10 ms, independent each way
  for (int64_t c : {40'000, -25'000}) {
    Diagnostics diag;
    ClockOffsetEstimator est;
    int64_t t = 1'700'000'000'000'000;
    for (int i = 0; i < 20; ++i, t += 1'000'000) {
      const auto e = exchange(t, c, delay(rng), delay(rng));
      ASSERT_TRUE(est.add(e, diag));
      // The bound holds after every exchange, whatever the delays.
      ASSERT_LE(std::llabs(*est.offset() + c), *est.errorBound()) << "exchange " << i;
    }
    // The smallest round trip of 16 is close to 2 × 10 ms, so the asymmetry left is small.
    EXPECT_LE(std::llabs(*est.offset() + c), 5'000) << "offset " << c;
    EXPECT_LE(*est.errorBound(), 15'000);
    EXPECT_EQ(diag.total(), 0);
  }
}

TEST(ClockOffset, TheSmallestRoundTripWins) {
  Diagnostics diag;
  ClockOffsetEstimator est(ClockOffsetOptions{4, 1'000'000});
  const int64_t c = 40'000;
  est.add(exchange(0, c, 30'000, 10'000), diag);  // δ 40 ms, θ̂ off by +10 ms
  est.add(exchange(1'000'000, c, 11'000, 11'000), diag);  // δ 22 ms, exact
  est.add(exchange(2'000'000, c, 10'000, 30'000), diag);  // δ 40 ms, off by −10 ms
  EXPECT_EQ(*est.offset(), -c);
  EXPECT_EQ(*est.errorBound(), 11'000);
  // It leaves the window after 4 more exchanges.
  for (int i = 0; i < 4; ++i) est.add(exchange(3'000'000 + i * 1'000'000, c, 30'000, 10'000), diag);
  EXPECT_EQ(*est.offset(), -c + 10'000);
}

TEST(ClockOffset, InconsistentAndSlowExchangesAreRefusedAndCounted) {
  Diagnostics diag;
  ClockOffsetEstimator est;
  EXPECT_FALSE(est.offset());
  ClockExchange backwards{1000, 5000, 6000, 900};  // reply before request
  EXPECT_FALSE(est.add(backwards, diag));
  ClockExchange negative_rtt{1000, 5000, 9000, 2000};  // the reference took longer than the round trip
  EXPECT_FALSE(est.add(negative_rtt, diag));
  ClockExchange absurd{INT64_MIN, 0, 0, 0};
  EXPECT_FALSE(est.add(absurd, diag));
  EXPECT_EQ(diag.get("time_sync:bad_exchange"), 3);
  EXPECT_FALSE(est.add(exchange(0, 0, 700'000, 700'000), diag));  // 1.4 s round trip
  EXPECT_EQ(diag.get("time_sync:slow_exchange"), 1);
  EXPECT_FALSE(est.offset());
  EXPECT_EQ(est.accepted(), 0);
  EXPECT_THROW(ClockOffsetEstimator(ClockOffsetOptions{0, 1}), std::invalid_argument);
}
