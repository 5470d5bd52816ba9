/// @file fuzz_flight_state_csv.cpp
/// @brief Fuzz target: flight_state.csv through readFlightStateCsv (samples in time order).
#include "common/dataset.h"
#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/sample_checks.h"
#include "fuzz/support/scratch_file.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static fuzz::ScratchFile file("flight_state.csv");
  file.write(data, size);
  Diagnostics diag;
  fuzz::refusalsAllowed([&] { fuzz::requireTimeSorted(readFlightStateCsv(file.path(), diag), "flight_state.csv"); });
  return 0;
}
