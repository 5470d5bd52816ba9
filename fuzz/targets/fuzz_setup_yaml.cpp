/// @file fuzz_setup_yaml.cpp
/// @brief Fuzz target: setup.yaml through loadSetup, and the same bytes as truth.yaml through
/// loadTruth (both YAML files of a dataset folder). Refusals are std::runtime_error; what a
/// refusal says and which values count as out of range is checked by the unit tests of setup.
#include "common/setup.h"
#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/scratch_file.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static fuzz::ScratchFile setup_file("setup.yaml");
  setup_file.write(data, size);
  fuzz::refusalsAllowed([&] {
    const SystemSetup s = loadSetup(setup_file.path());
    for (const auto& [id, p] : s.rel_tag_positions) (void)s.isKnownAnchor(id);
    for (const auto& b : s.pair_biases) (void)s.findPairBias(b.a, b.b);
  });
  fuzz::refusalsAllowed([&] { (void)loadTruth(setup_file.path()); });
  return 0;
}
