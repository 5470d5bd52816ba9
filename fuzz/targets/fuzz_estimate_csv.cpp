/// @file fuzz_estimate_csv.cpp
/// @brief Fuzz target: the estimator's outputs read back (common/estimate_io.h): the same bytes
/// through readPosesAuto (estimate.csv or TUM, as `calibrate --poses` reads them) and
/// readAnchorsCsv (anchors.csv, read by the evaluation). Accepted poses are finite with a unit
/// quaternion; accepted anchors have finite positions.
#include <cmath>

#include "common/estimate_io.h"
#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/sample_checks.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = fuzz::scratchFile("estimate.csv", data, size);
  Diagnostics diag;
  fuzz::refusalsAllowed([&] {
    for (const PoseSample& p : readPosesAuto(path, diag)) fuzz::requireFinitePose(p, "estimate.csv");
  });
  fuzz::refusalsAllowed([&] {
    for (const AnchorEstimate& a : readAnchorsCsv(path, diag))
      fuzz::require(a.p_AinG.allFinite() && a.cov_p_m2.allFinite(), "anchors.csv: non-finite anchor accepted");
  });
  return 0;
}
