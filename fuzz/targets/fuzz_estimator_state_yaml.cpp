/// @file fuzz_estimator_state_yaml.cpp
/// @brief Fuzz target: the restart checkpoint's estimator_state.yaml (layout 2, docs/formats.md)
/// through readCheckpoint. Refusals are std::runtime_error; an accepted checkpoint holds a unit
/// quaternion and only instances of registered kinds whose covariance fits their value.
#include <cmath>

#include "estimator/restart/checkpoint.h"
#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/scratch_file.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static fuzz::ScratchFile file("estimator_state.yaml");
  file.write(data, size);
  fuzz::refusalsAllowed([&] {
    const auto c = estimator::readCheckpoint(file.dir());
    fuzz::require(c.has_value(), "estimator_state.yaml: present but not read");
    fuzz::require(std::abs(c->imu.q_ItoG.norm() - 1.0) < 1e-9, "estimator_state.yaml: q_ItoG not normalized");
    for (const auto& r : c->instances) estimator::checkInstanceRecord(r);  // throws std::invalid_argument
  });
  return 0;
}
