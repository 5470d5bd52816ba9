/// @file fuzz_imu_csv.cpp
/// @brief Fuzz target: imu.csv through readImuCsv. Accepted rows are finite and within the
/// plausibility limits (500 m/s², 50 rad/s), in time order.
#include "common/dataset.h"
#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/sample_checks.h"
#include "fuzz/support/scratch_file.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static fuzz::ScratchFile file("imu.csv");
  file.write(data, size);
  Diagnostics diag;
  fuzz::refusalsAllowed([&] {
    const auto v = readImuCsv(file.path(), diag);
    for (const auto& s : v) {
      fuzz::require(s.acc_m_s2.allFinite() && s.gyro_rad_s.allFinite(), "imu.csv: non-finite value accepted");
      fuzz::require(s.acc_m_s2.norm() <= plausible::kMaxSpecificForce_m_s2 &&
                        s.gyro_rad_s.norm() <= plausible::kMaxAngularRate_rad_s,
                    "imu.csv: absurd reading accepted");
    }
    fuzz::requireTimeSorted(v, "imu.csv");
  });
  return 0;
}
