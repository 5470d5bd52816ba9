/// @file fuzz_height_csv.cpp
/// @brief Fuzz target: height.csv through readHeightCsv. Accepted ranges are in [0, 100] m, in
/// time order.
#include "common/dataset.h"
#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/sample_checks.h"
#include "fuzz/support/scratch_file.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static fuzz::ScratchFile file("height.csv");
  file.write(data, size);
  Diagnostics diag;
  fuzz::refusalsAllowed([&] {
    const auto v = readHeightCsv(file.path(), diag);
    for (const auto& s : v)
      fuzz::require(s.range_m >= 0.0 && s.range_m <= plausible::kMaxHeight_m,
                    "height.csv: height outside [0, 100] m or non-finite accepted");
    fuzz::requireTimeSorted(v, "height.csv");
  });
  return 0;
}
