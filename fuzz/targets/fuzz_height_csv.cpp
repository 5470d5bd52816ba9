/// @file fuzz_height_csv.cpp
/// @brief Fuzz target: height.csv through readHeightCsv. Accepted ranges are in [0, 100] m, in
/// time order.
#include "common/dataset.h"
#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/sample_checks.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::csvTarget("height.csv", data, size, readHeightCsv, [](const HeightSample& s) {
    fuzz::require(s.range_m >= 0.0 && s.range_m <= plausible::kMaxHeight_m,
                  "height.csv: height outside [0, 100] m or non-finite accepted");
  });
}
