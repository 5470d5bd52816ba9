/// @file fuzz_baro_csv.cpp
/// @brief Fuzz target: baro.csv through readBaroCsv. Accepted pressures are inside the plausible
/// interval, in time order.
#include "common/dataset.h"
#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/sample_checks.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::csvTarget("baro.csv", data, size, readBaroCsv, [](const BaroSample& s) {
    fuzz::require(s.pressure_pa >= plausible::kMinPressure_pa && s.pressure_pa <= plausible::kMaxPressure_pa,
                  "baro.csv: implausible or non-finite pressure accepted");
  });
}
