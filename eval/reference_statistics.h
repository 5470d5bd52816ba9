#pragma once
/// @file reference_statistics.h
/// @brief Reader of the range toolbox's `statistics.yaml` (published as reference_statistics.yaml).
///
/// Layout: a header document (not valid YAML as a whole: a mapping followed by a flow mapping of
/// the id lists), then one document per initiator `--- {ID: i, contant_bias_table: {j: b_ij},
/// noise_table: {j: σ_ij}}` (key spelled `contant_…` by the toolbox; `constant_…` is accepted too).
/// Values in metres, rounded to 2 decimals.
///
/// Sign: on the published real recording every table entry is the negative of mean(z − d) of the
/// same data (checked on all 12 pairs, |b| up to 0.42 m), i.e. the toolbox table holds d − z, a
/// correction. `toGamma()` converts it to the range model's γ = E[z − d] used everywhere here.

#include <map>
#include <string>

#include "common/types.h"

namespace meshnav::eval {

struct ReferencePairStats {
  double bias_table_m = 0.0;  ///< as written in the file (d − z convention) [m]
  double noise_m = 0.0;       ///< noise std [m]
  double toGamma() const { return -bias_table_m; }
};

/// (ID1, ID2) → statistics. Throws std::runtime_error naming the file on a malformed document.
std::map<std::pair<SensorId, SensorId>, ReferencePairStats> readReferenceStatistics(const std::string& path);

}  // namespace meshnav::eval
