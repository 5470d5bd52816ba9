#pragma once
/// @file range_csv_import.h
/// @brief Import of ranges in the published CSV format (`t,range_raw,range_corr,R,UWB_ID1,UWB_ID2,
/// type_ID1,type_ID2,LOS`, types 'T'/'A' or ASCII codes 84/65), given as one or more files — e.g.
/// one file per device as in the real recording (a01_ranges.csv, ..., d01_ranges.csv) — merged
/// into one time-sorted stream. Bad rows are reported with file:line and counted (common/dataset.h).

#include <set>
#include <string>
#include <vector>

#include "common/dataset.h"
#include "common/diagnostics.h"
#include "common/types.h"

namespace meshnav::uwb {

/// Reads every file, merges and sorts by time (stable: equal times keep the order of `paths`).
/// Throws std::runtime_error when a file is missing or lacks a required column.
std::vector<RangeSample> importRangeCsv(const std::vector<std::string>& paths, Diagnostics& diag,
                                        const RangeLimits& limits = {});

/// Keeps the ranges whose initiator (UWB_ID1) is in `initiators` (all when it is empty), in their
/// order: what the computer of one anchor publishes in a multi-host deployment, where each device
/// reports the ranges it initiated. Returns the number of ranges removed.
size_t keepInitiators(std::vector<RangeSample>& ranges, const std::set<SensorId>& initiators);

/// Splits "a.csv,b.csv" (and trims blanks) into paths.
std::vector<std::string> splitPathList(const std::string& list);

}  // namespace meshnav::uwb
