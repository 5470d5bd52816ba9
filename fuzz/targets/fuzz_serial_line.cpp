/// @file fuzz_serial_line.cpp
/// @brief Fuzz target: the serial line parser of uwb_bridge (SerialLineParser), fed the input as the
/// LineReader would: split at '\n', each piece at most LineReader::kMaxLine bytes. Every line is
/// either a range within the limits, skipped (blank/comment) or malformed and counted; ids and
/// device types follow the options.
#include <string>

#include "fuzz/support/fuzz_target.h"
#include "uwb_bridge/line_reader.h"
#include "uwb_bridge/serial_line_parser.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  Diagnostics diag;
  uwb::SerialParserOptions options;
  options.tag_ids = {100, 105};
  uwb::SerialLineParser parser(options, diag, "fuzz-serial");
  int64_t lines = 0;
  int64_t skipped = 0;
  fuzz::refusalsAllowed([&] {
    size_t begin = 0;
    while (begin < text.size()) {
      size_t end = text.find('\n', begin);
      if (end == std::string::npos) end = text.size();
      if (end - begin > uwb::LineReader::kMaxLine) end = begin + uwb::LineReader::kMaxLine;
      const auto r = parser.parse(text.substr(begin, end - begin), Timestamp::fromUtime(1000 * (lines + 1)));
      ++lines;
      begin = end < text.size() && text[end] == '\n' ? end + 1 : end;
      if (r.outcome == uwb::SerialLineParser::Outcome::Skipped) ++skipped;
      if (r.outcome == uwb::SerialLineParser::Outcome::Malformed) fuzz::require(!r.reason.empty(), "malformed line without a reason");
      if (r.outcome != uwb::SerialLineParser::Outcome::Range) continue;
      const RangeSample& s = r.range;
      fuzz::require(s.range_m >= options.limits.min_m && s.range_m <= options.limits.max_m, "range outside the limits accepted");
      fuzz::require(s.id_initiator != s.id_responder && s.id_initiator >= 0 && s.id_responder >= 0, "bad ids accepted");
      fuzz::require((s.type_initiator == UwbType::Tag) == (options.tag_ids.count(s.id_initiator) > 0), "initiator type wrong");
      fuzz::require(r.seq >= 0, "range without a sequence number");
    }
  });
  fuzz::require(parser.linesSeen() == lines, "lines seen differ from lines given");
  fuzz::require(parser.rangesParsed() + parser.malformed() + skipped == lines, "a line neither parsed, skipped nor counted");
  return 0;
}
