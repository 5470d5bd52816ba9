/// @file fuzz_flight_state_csv.cpp
/// @brief Fuzz target: flight_state.csv through readFlightStateCsv (samples in time order).
#include "common/dataset.h"
#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/sample_checks.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::csvTarget("flight_state.csv", data, size, readFlightStateCsv, [](const FlightStateSample&) {});
}
