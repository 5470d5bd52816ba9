/// @file fuzz_groundtruth_csv.cpp
/// @brief Fuzz target: groundtruth.csv (TUM) through readTumCsv. Accepted poses are finite with a
/// unit quaternion, in time order.
#include <cmath>

#include "common/dataset.h"
#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/sample_checks.h"
#include "fuzz/support/scratch_file.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static fuzz::ScratchFile file("groundtruth.csv");
  file.write(data, size);
  Diagnostics diag;
  fuzz::refusalsAllowed([&] {
    const auto v = readTumCsv(file.path(), diag);
    for (const auto& s : v) {
      fuzz::require(s.p_IinG.allFinite() && s.q_ItoG.coeffs().allFinite(), "groundtruth.csv: non-finite pose accepted");
      fuzz::require(std::abs(s.q_ItoG.norm() - 1.0) < 1e-6, "groundtruth.csv: quaternion not normalized");
    }
    fuzz::requireTimeSorted(v, "groundtruth.csv");
  });
  return 0;
}
