#include "uwb_bridge/serial_line_parser.h"

#include <spdlog/fmt/fmt.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <vector>

namespace meshnav::uwb {
namespace {

std::vector<std::string> splitFields(const std::string& s) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s) {
    if (c == ' ' || c == '\t' || c == ',' || c == ';') {
      if (!cur.empty()) out.push_back(std::move(cur));
      cur.clear();
    } else {
      cur.push_back(c);
    }
  }
  if (!cur.empty()) out.push_back(std::move(cur));
  return out;
}

/// A non-negative decimal integer that fits an int32 (ids) or int64 (seq).
std::optional<int64_t> parseNonNegInt(const std::string& s, int64_t max) {
  if (s.empty() || s.size() > 19) return std::nullopt;
  for (char c : s)
    if (c < '0' || c > '9') return std::nullopt;
  errno = 0;
  const long long v = std::strtoll(s.c_str(), nullptr, 10);
  if (errno != 0 || v > max) return std::nullopt;
  return v;
}

std::optional<double> parseDouble(const std::string& s) {
  if (s.empty()) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size()) return std::nullopt;
  return v;  // may be NaN or inf: the caller reports it as such
}

}  // namespace

SerialLineParser::SerialLineParser(SerialParserOptions options, Diagnostics& diag, std::string source)
    : options_(std::move(options)), diag_(diag), source_(std::move(source)) {}

SerialLineParser::Result SerialLineParser::fail(const std::string& kind, const std::string& reason) {
  ++n_malformed_;
  diag_.report("serial:" + kind, source_ + ":" + std::to_string(line_) + ": " + reason + "; line skipped");
  Result r;
  r.outcome = Outcome::Malformed;
  r.reason = reason;
  return r;
}

SerialLineParser::Result SerialLineParser::parse(const std::string& raw, Timestamp t_receipt) {
  ++line_;
  std::string line = raw;
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
  const auto first = line.find_first_not_of(" \t");
  if (first == std::string::npos || line[first] == '#') return Result{};  // blank or comment

  std::string shown = line.substr(first, 60);
  for (char& c : shown)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
  const auto fields = splitFields(line.substr(first));
  if (fields.size() != 4)
    return fail("malformed", "expected 'seq ID1 ID2 range_m', got " + std::to_string(fields.size()) +
                                 " fields in '" + shown + "'");
  const auto seq = parseNonNegInt(fields[0], INT64_MAX);
  if (!seq) return fail("malformed", "sequence number '" + fields[0] + "' is not a non-negative integer");
  // Gaps in the sequence numbers are lines lost on the way (a line that arrived but is invalid
  // is counted as malformed, not lost).
  // A jump beyond kMaxSeqGap is a corrupted or reset counter, not lost lines: counted apart, so
  // that the gap count stays meaningful (and cannot overflow).
  if (last_seq_ && *seq > *last_seq_ && *seq - *last_seq_ > 1) {
    const int64_t lost = *seq - *last_seq_ - 1;
    if (lost <= kMaxSeqGap) {
      n_gap_ += lost;
      diag_.count("serial:seq_gap", lost);
    } else {
      diag_.report("serial:seq_jump", source_ + ":" + std::to_string(line_) + ": sequence number jumps from " +
                                          std::to_string(*last_seq_) + " to " + std::to_string(*seq) +
                                          " (not counted as lost lines)");
    }
  }
  last_seq_ = *seq;
  const auto id1 = parseNonNegInt(fields[1], INT32_MAX);
  const auto id2 = parseNonNegInt(fields[2], INT32_MAX);
  if (!id1 || !id2) return fail("bad_id", "UWB ids '" + fields[1] + "', '" + fields[2] + "' are not non-negative integers");
  if (*id1 == *id2) return fail("self_range", "range from device " + fields[1] + " to itself");
  const auto z = parseDouble(fields[3]);
  if (!z) return fail("malformed", "range '" + fields[3] + "' is not a number");
  if (!std::isfinite(*z)) return fail("nan_range", "range '" + fields[3] + "' is not a finite number");
  if (*z < options_.limits.min_m)
    return fail("negative_range", "range " + fields[3] + " m is below " + fmt::format("{:g}", options_.limits.min_m) + " m");
  if (*z > options_.limits.max_m)
    return fail("absurd_range", "range " + fields[3] + " m exceeds " + fmt::format("{:g}", options_.limits.max_m) + " m");

  Result r;
  r.outcome = Outcome::Range;
  r.seq = *seq;
  RangeSample& s = r.range;
  s.t = t_receipt;
  s.id_initiator = static_cast<SensorId>(*id1);
  s.id_responder = static_cast<SensorId>(*id2);
  s.type_initiator = options_.tag_ids.count(s.id_initiator) ? UwbType::Tag : UwbType::Anchor;
  s.type_responder = options_.tag_ids.count(s.id_responder) ? UwbType::Tag : UwbType::Anchor;
  s.range_m = *z;
  s.range_corr_m = *z;   // the driver applies no correction: the corrected range is the raw one
  s.R_m2 = 0.0;          // unknown
  s.los = true;
  ++n_ranges_;
  return r;
}

}  // namespace meshnav::uwb
