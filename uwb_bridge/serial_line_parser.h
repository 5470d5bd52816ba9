#pragma once
/// @file serial_line_parser.h
/// @brief Parser of the serial output of the public UWB two-way-ranging firmware driver: one range
/// per line, `seq ID1 ID2 range_m`, fields separated by spaces, tabs, commas or semicolons
/// (e.g. "17 0 1 4.4652" or "17,0,1,4.4652"). ID1 is the initiator. Lines starting with '#' and
/// blank lines are skipped. Every other line that is not a valid range is reported with
/// `<source>:<line>` and counted in Diagnostics ("serial:<kind>"), never passed on.
///
/// The line carries no time: the caller stamps it on receipt. It carries no device type either:
/// ids listed in `tag_ids` are tags ('T'), all others anchors ('A').

#include <cstdint>
#include <optional>
#include <set>
#include <string>

#include "common/dataset.h"
#include "common/diagnostics.h"
#include "common/types.h"

namespace meshnav::uwb {

struct SerialParserOptions {
  std::set<SensorId> tag_ids;  ///< devices that are tags; every other id is an anchor
  RangeLimits limits;          ///< plausible range interval [m] (as for ranges.csv)
};

class SerialLineParser {
 public:
  enum class Outcome { Range, Skipped, Malformed };
  struct Result {
    Outcome outcome = Outcome::Skipped;
    RangeSample range;       ///< valid when outcome == Range
    int64_t seq = -1;        ///< sequence number of the line, when it parsed
    std::string reason;      ///< why a line was malformed ("" otherwise)
  };

  SerialLineParser(SerialParserOptions options, Diagnostics& diag, std::string source = "serial");

  /// Parses the next line (trailing "\r\n" allowed), received at `t_receipt`.
  Result parse(const std::string& line, Timestamp t_receipt);

  int64_t linesSeen() const { return line_; }
  int64_t rangesParsed() const { return n_ranges_; }
  int64_t malformed() const { return n_malformed_; }
  /// Lines lost according to the sequence numbers (gaps between consecutive seq) [-]. A forward
  /// jump of more than kMaxSeqGap lines is a corrupted or reset counter: reported as
  /// "serial:seq_jump", not counted here.
  int64_t seqGaps() const { return n_gap_; }
  static constexpr int64_t kMaxSeqGap = 65535;

 private:
  Result fail(const std::string& kind, const std::string& reason);

  SerialParserOptions options_;
  Diagnostics& diag_;
  std::string source_;
  int64_t line_ = 0;
  int64_t n_ranges_ = 0;
  int64_t n_malformed_ = 0;
  int64_t n_gap_ = 0;
  std::optional<int64_t> last_seq_;
};

}  // namespace meshnav::uwb
