/// @file fuzz_estimate_csv.cpp
/// @brief Fuzz target: the estimator's outputs read back (common/estimate_io.h): the same bytes
/// through readPosesAuto (estimate.csv or TUM, as `calibrate --poses` reads them) and
/// readAnchorsCsv (anchors.csv, read by the evaluation). Accepted poses are finite with a unit
/// quaternion; accepted anchors have finite positions.
#include <cmath>

#include "common/estimate_io.h"
#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/scratch_file.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static fuzz::ScratchFile file("estimate.csv");
  file.write(data, size);
  Diagnostics diag;
  fuzz::refusalsAllowed([&] {
    for (const PoseSample& p : readPosesAuto(file.path(), diag)) {
      fuzz::require(p.p_IinG.allFinite() && p.q_ItoG.coeffs().allFinite(), "estimate.csv: non-finite pose accepted");
      fuzz::require(std::abs(p.q_ItoG.norm() - 1.0) < 1e-6, "estimate.csv: quaternion not normalized");
    }
  });
  fuzz::refusalsAllowed([&] {
    for (const AnchorEstimate& a : readAnchorsCsv(file.path(), diag))
      fuzz::require(a.p_AinG.allFinite() && a.cov_p_m2.allFinite(), "anchors.csv: non-finite anchor accepted");
  });
  return 0;
}
