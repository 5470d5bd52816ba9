/// Timestamp / Duration conversion from seconds: values that do not fit are refused (issue 12,
/// finding 2: 1e308 s became INT64_MIN and sorted first).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/dataset.h"
#include "common/time.h"
#include "tests/support/test_util.h"

using namespace meshnav;

TEST(Time, FromSecRoundsToMicroseconds) {
  EXPECT_EQ(Timestamp::fromSec(1.2345674).us, 1234567);
  EXPECT_EQ(Timestamp::fromSec(-2.5).us, -2500000);
  EXPECT_EQ(Duration::fromSec(0.0000015).us, 2);
  EXPECT_EQ(Duration::fromMs(1.5).us, 1500);
  EXPECT_EQ(Timestamp::fromSec(kMaxTimeSeconds).us, static_cast<int64_t>(kMaxTimeSeconds * 1e6));
}

TEST(Time, ValuesThatDoNotFitAreRefused) {
  for (double s : {1e308, -1e308, 1e13, -1e13, std::numeric_limits<double>::infinity(),
                   std::numeric_limits<double>::quiet_NaN()}) {
    EXPECT_THROW(Timestamp::fromSec(s), std::out_of_range) << s;
    EXPECT_THROW(Duration::fromSec(s), std::out_of_range) << s;
    EXPECT_FALSE(Timestamp::tryFromSec(s).has_value()) << s;
    EXPECT_FALSE(Duration::tryFromSec(s).has_value()) << s;
  }
  EXPECT_THROW(Duration::fromMs(1e300), std::out_of_range);
  ASSERT_TRUE(Timestamp::tryFromSec(1.7e9).has_value());  // a Unix time
  EXPECT_EQ(Timestamp::tryFromSec(1.7e9)->us, 1700000000000000);
}

TEST(Time, FormatSecondsHandlesEveryInt64) {
  EXPECT_EQ(formatSeconds(Timestamp{-1500000}), "-1.500000");
  EXPECT_EQ(formatSeconds(Timestamp{0}), "0.000000");
  EXPECT_EQ(formatSeconds(Timestamp{1}), "0.000001");
  EXPECT_EQ(formatSeconds(Timestamp{-1}), "-0.000001");
  EXPECT_EQ(formatSeconds(Timestamp{140010000}), "140.010000");
  EXPECT_EQ(formatSeconds(Timestamp{std::numeric_limits<int64_t>::min()}), "-9223372036854.775808");
  EXPECT_EQ(formatSeconds(Timestamp{std::numeric_limits<int64_t>::max()}), "9223372036854.775807");
}

TEST(Time, CsvTimesThatDoNotFitAreReportedWithFileAndLine) {
  const test::TempDir d("time");
  const auto f = test::writeFile(d / "ranges.csv",
                                 "t,range_raw,UWB_ID1,UWB_ID2,type_ID1,type_ID2\n"
                                 "1.0,4.0,100,101,T,A\n"
                                 "1e308,4.0,100,101,T,A\n"    // would have become INT64_MIN
                                 "-1e13,4.0,100,101,T,A\n"
                                 "2.0,4.0,100,101,T,A\n");
  Diagnostics diag;
  const auto r = readRangesCsv(f, diag);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r.front().t, Timestamp::fromSec(1.0));
  EXPECT_EQ(r.back().t, Timestamp::fromSec(2.0));
  EXPECT_EQ(diag.get("ranges.csv:bad_time"), 2);
  EXPECT_EQ(diag.get("ranges.csv:time_backwards"), 0);
}
