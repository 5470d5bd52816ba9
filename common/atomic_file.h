#pragma once
/// @file atomic_file.h
/// @brief Files written once (status, timings, metrics, summaries, calibration results, datasets,
/// checkpoints): complete or not there at all (issue 36, item 1).
///
/// The text goes to `<path>.tmp`; the stream is checked after the writer and after its close, and
/// only then is the temporary renamed over `path` (a rename within a folder is atomic on POSIX).
/// A failed write (a full disk, a read-only folder, a signal) removes the temporary, leaves an
/// older `path` as it was, and throws std::runtime_error "<path>: write failed (<reason>; nothing
/// written)". Streamed files (estimate.csv, anchors.csv, the logger's CSVs) are checked at every
/// flush instead (checkedFlush, common/estimate_io.h).

#include <functional>
#include <ostream>
#include <string>

namespace meshnav {

/// Writes `path` through `write(stream)` as above; creates the parent folder.
void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace meshnav
