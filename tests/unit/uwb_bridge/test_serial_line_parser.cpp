// The serial line format of the UWB TWR firmware driver: `seq ID1 ID2 range_m`, on real-looking
// input: good lines in every separator style, comments, garbage, NaN, negative and absurd ranges.
#include <gtest/gtest.h>

#include "uwb_bridge/serial_line_parser.h"

using namespace meshnav;
using namespace meshnav::uwb;
using Outcome = SerialLineParser::Outcome;

namespace {

SerialParserOptions tagZero() {
  SerialParserOptions o;
  o.tag_ids = {0};
  return o;
}

}  // namespace

TEST(SerialLineParser, GoodLinesInEverySeparatorStyle) {
  Diagnostics diag;
  SerialLineParser p(tagZero(), diag, "/dev/ttyACM0");
  const Timestamp t{1693508300597519};
  const char* lines[] = {"1 0 1 4.465219974517822", "2,0,2,5.168773174285889\r\n", "3\t1\t0\t4.4277",
                         "4, 2, 3, 6.55242919921875", "  5 3 0 4.0899  ", "6;1;2;2.9127"};
  for (const char* l : lines) {
    const auto r = p.parse(l, t);
    ASSERT_EQ(r.outcome, Outcome::Range) << l << ": " << r.reason;
  }
  EXPECT_EQ(p.rangesParsed(), 6);
  EXPECT_EQ(p.malformed(), 0);
  EXPECT_EQ(p.seqGaps(), 0);
  EXPECT_EQ(diag.total(), 0);

  SerialLineParser q(tagZero(), diag);
  const auto r = q.parse("17 0 1 4.465219974517822", t);
  EXPECT_EQ(r.seq, 17);
  EXPECT_EQ(r.range.t, t);  // stamped on receipt
  EXPECT_EQ(r.range.id_initiator, 0);
  EXPECT_EQ(r.range.id_responder, 1);
  EXPECT_EQ(r.range.type_initiator, UwbType::Tag);
  EXPECT_EQ(r.range.type_responder, UwbType::Anchor);
  EXPECT_DOUBLE_EQ(r.range.range_m, 4.465219974517822);
  const auto aa = q.parse("18 2 3 6.5", t);
  EXPECT_EQ(aa.range.type_initiator, UwbType::Anchor);
  EXPECT_EQ(aa.range.type_responder, UwbType::Anchor);
}

TEST(SerialLineParser, CommentsAndBlankLinesAreSkippedButCounted) {
  Diagnostics diag;
  SerialLineParser p(tagZero(), diag);
  EXPECT_EQ(p.parse("# uwb_driver v1.2 started", Timestamp{}).outcome, Outcome::Skipped);
  EXPECT_EQ(p.parse("", Timestamp{}).outcome, Outcome::Skipped);
  EXPECT_EQ(p.parse("   \r", Timestamp{}).outcome, Outcome::Skipped);
  EXPECT_EQ(p.parse("   # indented comment", Timestamp{}).outcome, Outcome::Skipped);
  EXPECT_EQ(p.linesSeen(), 4);
  EXPECT_EQ(p.malformed(), 0);
  EXPECT_EQ(diag.total(), 0);
}

TEST(SerialLineParser, GarbageIsReportedWithLineNumber) {
  Diagnostics diag;
  SerialLineParser p(tagZero(), diag, "uwb.log");
  struct Case {
    const char* line;
    const char* kind;
  };
  const Case cases[] = {
      {"DW1000 init ok", "serial:malformed"},          // boot message: 3 fields
      {"1 0 1", "serial:malformed"},                   // too few fields
      {"1 0 1 4.5 -87.2", "serial:malformed"},         // too many
      {"x 0 1 4.5", "serial:malformed"},               // bad sequence number
      {"-3 0 1 4.5", "serial:malformed"},              // negative sequence number
      {"2 0 A1 4.5", "serial:bad_id"},                 // bad id
      {"3 -1 1 4.5", "serial:bad_id"},                 // negative id
      {"4 99999999999 1 4.5", "serial:bad_id"},        // id beyond int32
      {"5 1 1 4.5", "serial:self_range"},              // self range
      {"6 0 1 4.5m", "serial:malformed"},              // unit glued to the number
      {"\x01\x7f\xfe\xff", "serial:malformed"},        // line noise
  };
  int line = 0;
  for (const auto& c : cases) {
    ++line;
    const auto r = p.parse(c.line, Timestamp{});
    EXPECT_EQ(r.outcome, Outcome::Malformed) << c.line;
    EXPECT_FALSE(r.reason.empty());
  }
  EXPECT_EQ(p.malformed(), static_cast<int64_t>(std::size(cases)));
  EXPECT_EQ(diag.get("serial:malformed"), 7);
  EXPECT_EQ(diag.get("serial:bad_id"), 3);
  EXPECT_EQ(diag.get("serial:self_range"), 1);
  EXPECT_EQ(p.rangesParsed(), 0);
}

TEST(SerialLineParser, NonFiniteNegativeAndAbsurdRanges) {
  Diagnostics diag;
  SerialLineParser p(tagZero(), diag);
  EXPECT_EQ(p.parse("1 0 1 nan", Timestamp{}).outcome, Outcome::Malformed);
  EXPECT_EQ(p.parse("2 0 1 NaN", Timestamp{}).outcome, Outcome::Malformed);
  EXPECT_EQ(p.parse("3 0 1 inf", Timestamp{}).outcome, Outcome::Malformed);
  EXPECT_EQ(p.parse("4 0 1 -316918.125", Timestamp{}).outcome, Outcome::Malformed);  // seen in real data
  EXPECT_EQ(p.parse("5 0 1 -0.7", Timestamp{}).outcome, Outcome::Malformed);
  EXPECT_EQ(p.parse("6 0 1 1e9", Timestamp{}).outcome, Outcome::Malformed);
  // A biased short range may be slightly negative: kept (as for ranges.csv).
  const auto small = p.parse("7 0 1 -0.12", Timestamp{});
  ASSERT_EQ(small.outcome, Outcome::Range);
  EXPECT_DOUBLE_EQ(small.range.range_m, -0.12);
  EXPECT_EQ(p.parse("8 0 1 0", Timestamp{}).outcome, Outcome::Range);
  EXPECT_EQ(diag.get("serial:nan_range"), 3);
  EXPECT_EQ(diag.get("serial:negative_range"), 2);
  EXPECT_EQ(diag.get("serial:absurd_range"), 1);
}

TEST(SerialLineParser, CustomLimits) {
  Diagnostics diag;
  SerialParserOptions o;
  o.limits.min_m = 0.0;
  o.limits.max_m = 50.0;
  SerialLineParser p(o, diag);
  EXPECT_EQ(p.parse("1 0 1 -0.01", Timestamp{}).outcome, Outcome::Malformed);
  EXPECT_EQ(p.parse("2 0 1 51", Timestamp{}).outcome, Outcome::Malformed);
  EXPECT_EQ(p.parse("3 0 1 49.9", Timestamp{}).outcome, Outcome::Range);
}

TEST(SerialLineParser, SequenceGapsCountLostLines) {
  Diagnostics diag;
  SerialLineParser p(tagZero(), diag);
  p.parse("10 0 1 4.0", Timestamp{});
  p.parse("11 0 2 4.0", Timestamp{});
  p.parse("12 0 3 nan", Timestamp{});  // arrived (malformed), not lost
  p.parse("15 0 1 4.0", Timestamp{});  // 13, 14 lost
  p.parse("3 0 1 4.0", Timestamp{});   // counter restart (firmware reboot): not a gap
  p.parse("4 0 1 4.0", Timestamp{});
  EXPECT_EQ(p.seqGaps(), 2);
  EXPECT_EQ(diag.get("serial:seq_gap"), 2);
}

// Found by fuzz target serial_line (UBSan: signed overflow in last_seq + 1): a sequence number of
// INT64_MAX followed by other lines. A jump beyond kMaxSeqGap is a reset or corrupted counter,
// reported but not counted as lost lines (the count could overflow otherwise).
TEST(SerialLineParser, LargestSequenceNumberDoesNotOverflow) {
  Diagnostics diag;
  SerialLineParser p(tagZero(), diag);
  for (const char* l : {"9223372036854775807 0 1 4.0", "23 0 1 4.0", "9223372036854775807 0 1 4.0", "0 0 1 4.0",
                        "9223372036854775807 0 1 4.0", "9223372036854775807 0 1 4.0"})
    EXPECT_EQ(p.parse(l, Timestamp{}).outcome, Outcome::Range) << l;
  EXPECT_EQ(p.seqGaps(), 0);
  EXPECT_EQ(diag.get("serial:seq_jump"), 2);

  // kMaxSeqGap lost lines are still counted as lost; one more is a jump.
  Diagnostics diag2;
  SerialLineParser q(tagZero(), diag2);
  const int64_t k = SerialLineParser::kMaxSeqGap;
  q.parse("0 0 1 4.0", Timestamp{});
  q.parse(std::to_string(k + 1) + " 0 1 4.0", Timestamp{});
  EXPECT_EQ(q.seqGaps(), k);
  q.parse(std::to_string(2 * k + 3) + " 0 1 4.0", Timestamp{});
  EXPECT_EQ(q.seqGaps(), k);
  EXPECT_EQ(diag2.get("serial:seq_jump"), 1);
}
