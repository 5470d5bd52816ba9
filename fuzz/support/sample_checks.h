#pragma once
/// @file sample_checks.h
/// @brief Promises of the dataset readers (common/dataset.h) that fuzz targets check on what a
/// reader accepted: samples sorted by time, every value finite and inside the reader's limits.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz/support/fuzz_target.h"
#include "fuzz/support/scratch_file.h"
#include "common/diagnostics.h"

namespace meshnav::fuzz {

/// Every sample at or after the one before it (readers sort a file whose time goes backwards).
template <class Sample>
void requireTimeSorted(const std::vector<Sample>& v, const std::string& file) {
  for (size_t i = 1; i < v.size(); ++i)
    require(!(v[i].t < v[i - 1].t), file + ": reader returned samples out of time order");
}

/// A finite pose with a unit quaternion (ground truth and the estimator's output read back).
template <class Pose>
void requireFinitePose(const Pose& p, const std::string& file) {
  require(p.p_IinG.allFinite() && p.q_ItoG.coeffs().allFinite(), file + ": non-finite pose accepted");
  require(std::abs(p.q_ItoG.norm() - 1.0) < 1e-6, file + ": quaternion not normalized");
}

/// The bytes as the file `name` (its base name: readers use it in their counter keys), kept in a
/// scratch folder for the process's lifetime.
inline const std::string& scratchFile(const std::string& name, const uint8_t* data, size_t size) {
  static ScratchFile file(name);
  return file.write(data, size);
}

/// The whole of a dataset CSV target: the bytes become the file `name`, `read(path, diag)` reads
/// it (a refusal is fine), `check` runs on every sample it accepted and they must be in time order.
template <class Read, class Check>
int csvTarget(const std::string& name, const uint8_t* data, size_t size, Read&& read, Check&& check) {
  const std::string& path = scratchFile(name, data, size);
  Diagnostics diag;
  refusalsAllowed([&] {
    const auto v = read(path, diag);
    for (const auto& s : v) check(s);
    requireTimeSorted(v, name);
  });
  return 0;
}

}  // namespace meshnav::fuzz
