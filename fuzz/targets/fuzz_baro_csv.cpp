/// @file fuzz_baro_csv.cpp
/// @brief Fuzz target: baro.csv through readBaroCsv. Accepted pressures are inside the plausible
/// interval, in time order.
#include "common/dataset.h"
#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/sample_checks.h"
#include "fuzz/support/scratch_file.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static fuzz::ScratchFile file("baro.csv");
  file.write(data, size);
  Diagnostics diag;
  fuzz::refusalsAllowed([&] {
    const auto v = readBaroCsv(file.path(), diag);
    for (const auto& s : v)
      fuzz::require(s.pressure_pa >= plausible::kMinPressure_pa && s.pressure_pa <= plausible::kMaxPressure_pa,
                    "baro.csv: implausible or non-finite pressure accepted");
    fuzz::requireTimeSorted(v, "baro.csv");
  });
  return 0;
}
