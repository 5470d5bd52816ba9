#pragma once
/// @file sample_checks.h
/// @brief Promises of the dataset readers (common/dataset.h) that fuzz targets check on what a
/// reader accepted: samples sorted by time, every value finite and inside the reader's limits.

#include <string>
#include <vector>

#include "fuzz/support/fuzz_target.h"

namespace meshnav::fuzz {

/// Every sample at or after the one before it (readers sort a file whose time goes backwards).
template <class Sample>
void requireTimeSorted(const std::vector<Sample>& v, const std::string& file) {
  for (size_t i = 1; i < v.size(); ++i)
    require(!(v[i].t < v[i - 1].t), file + ": reader returned samples out of time order");
}

}  // namespace meshnav::fuzz
