/// @file fuzz_imu_csv.cpp
/// @brief Fuzz target: imu.csv through readImuCsv. Accepted rows are finite and within the
/// plausibility limits (500 m/s², 50 rad/s), in time order.
#include "common/dataset.h"
#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/sample_checks.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::csvTarget("imu.csv", data, size, readImuCsv, [](const ImuSample& s) {
    fuzz::require(s.acc_m_s2.allFinite() && s.gyro_rad_s.allFinite(), "imu.csv: non-finite value accepted");
    fuzz::require(s.acc_m_s2.norm() <= plausible::kMaxSpecificForce_m_s2 &&
                      s.gyro_rad_s.norm() <= plausible::kMaxAngularRate_rad_s,
                  "imu.csv: absurd reading accepted");
  });
}
