/// @file fuzz_anchor_init_yaml.cpp
/// @brief Fuzz target: a calibration results file (docs/formats.md, "Calibration results (YAML)":
/// written by the calibrator and the logger, read back for the estimator and the evaluation)
/// through readAnchorInitsYaml.
/// Refusals are std::runtime_error; every accepted bias names its anchor.
#include "common/anchor_init_io.h"
#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/scratch_file.h"

using namespace meshnav;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static fuzz::ScratchFile file("anchors.yaml");
  file.write(data, size);
  fuzz::refusalsAllowed([&] {
    for (const AnchorInit& a : readAnchorInitsYaml(file.path()))
      for (const PairBias& b : a.biases) fuzz::require(b.b == a.id, "anchors.yaml: a bias of another anchor");
  });
  return 0;
}
