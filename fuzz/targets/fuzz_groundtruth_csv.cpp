/// @file fuzz_groundtruth_csv.cpp
/// @brief Fuzz target: groundtruth.csv (TUM) through readTumCsv. Accepted poses are finite with a
/// unit quaternion, in time order.
#include <cmath>

#include "common/dataset.h"
#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/sample_checks.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::csvTarget("groundtruth.csv", data, size, readTumCsv,
                         [](const PoseSample& s) { fuzz::requireFinitePose(s, "groundtruth.csv"); });
}
