#pragma once
/// @file dataset.h
/// @brief The dataset folder (docs/formats.md): imu.csv, baro.csv, ranges.csv, flight_state.csv,
/// groundtruth.csv, setup.yaml, truth.yaml, and the optional height.csv (`t,range_m`, downward
/// laser range [m], written by the MILUV importer). Readers validate every row: bad rows are reported
/// (file:line), counted in `Diagnostics`, and dropped; they never reach an estimator.

#include <optional>
#include <string>
#include <vector>

#include "common/diagnostics.h"
#include "common/plausibility.h"
#include "common/setup.h"
#include "common/types.h"

namespace meshnav {

struct Dataset {
  std::vector<ImuSample> imu;
  std::vector<BaroSample> baro;
  std::vector<RangeSample> ranges;
  std::vector<FlightStateSample> flight_states;
  std::vector<HeightSample> heights;  ///< optional height.csv
  std::vector<PoseSample> ground_truth;
  SystemSetup setup;
  std::optional<Truth> truth;
};

/// Limits used when validating ranges [m].
struct RangeLimits {
  double min_m = plausible::kMinRange_m;  ///< biased short ranges can be slightly negative
  double max_m = plausible::kMaxRange_m;  ///< beyond this a UWB range is absurd
};

std::vector<ImuSample> readImuCsv(const std::string& path, Diagnostics& diag);
std::vector<BaroSample> readBaroCsv(const std::string& path, Diagnostics& diag);
/// Reads the published range format `t,range_raw,range_corr,R,UWB_ID1,UWB_ID2,type_ID1,type_ID2,LOS`
/// (types as letters 'T'/'A' or ASCII codes 84/65). NaN, negative beyond limits or absurd ranges,
/// self-ranges and unknown type codes are reported and dropped.
std::vector<RangeSample> readRangesCsv(const std::string& path, Diagnostics& diag,
                                       const RangeLimits& limits = {});
std::vector<FlightStateSample> readFlightStateCsv(const std::string& path, Diagnostics& diag);
/// `t,range_m`; a range that is not finite, negative or beyond 100 m is reported and dropped.
std::vector<HeightSample> readHeightCsv(const std::string& path, Diagnostics& diag);
/// TUM format `#t,tx,ty,tz,qx,qy,qz,qw` (comma or space separated).
std::vector<PoseSample> readTumCsv(const std::string& path, Diagnostics& diag);

void writeImuCsv(const std::vector<ImuSample>& v, const std::string& path);
void writeBaroCsv(const std::vector<BaroSample>& v, const std::string& path);
void writeRangesCsv(const std::vector<RangeSample>& v, const std::string& path);
void writeFlightStateCsv(const std::vector<FlightStateSample>& v, const std::string& path);
void writeHeightCsv(const std::vector<HeightSample>& v, const std::string& path);
void writeTumCsv(const std::vector<PoseSample>& v, const std::string& path);

/// Reads a whole dataset folder. setup.yaml is required; the sensor files are optional except
/// ranges.csv; truth.yaml only when `with_truth`. Samples come back sorted by time (a time going
/// backwards in a file is reported as "<file>:time_backwards" and the file is sorted).
Dataset readDataset(const std::string& dir, Diagnostics& diag, bool with_truth = false);
/// Writes every non-empty part of `ds` into `dir` (created if needed).
void writeDataset(const Dataset& ds, const std::string& dir);

}  // namespace meshnav
