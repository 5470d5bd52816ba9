/// @file fuzz_ranges_csv.cpp
/// @brief Fuzz target: ranges.csv through readRangesCsv. Accepted ranges are finite and within the
/// limits, between two different devices with non-negative ids, in time order.
#include <cmath>

#include "common/dataset.h"
#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/sample_checks.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const RangeLimits limits;
  const auto read = [&](const std::string& path, Diagnostics& diag) { return readRangesCsv(path, diag, limits); };
  return fuzz::csvTarget("ranges.csv", data, size, read, [&](const RangeSample& s) {
    fuzz::require(s.range_m >= limits.min_m && s.range_m <= limits.max_m, "ranges.csv: range outside the limits accepted");
    fuzz::require(std::isfinite(s.range_corr_m) && std::isfinite(s.R_m2) && s.R_m2 >= 0.0,
                  "ranges.csv: non-finite range_corr or R accepted");
    fuzz::require(s.id_initiator != s.id_responder, "ranges.csv: self-range accepted");
    fuzz::require(s.id_initiator >= 0 && s.id_responder >= 0, "ranges.csv: negative id accepted");
  });
}
