#pragma once
/// @file csv.h
/// @brief Small CSV reader that knows file and line of every value, for clear bad-input messages.

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/diagnostics.h"
#include "common/time.h"

namespace meshnav {

/// One parsed data row; `get` returns NaN-free doubles or nullopt (the caller reports).
class CsvRow {
 public:
  const std::string& file() const { return *file_; }
  int line() const { return line_; }
  /// "file:line" for messages.
  std::string where() const;
  /// Numeric value of column `name`; nullopt when empty or not a finite number.
  std::optional<double> number(const std::string& name) const;
  /// Raw text of column `name` (trimmed).
  std::string text(const std::string& name) const;
  bool has(const std::string& name) const;

 private:
  friend class CsvReader;
  const std::string* file_ = nullptr;
  int line_ = 0;
  const std::map<std::string, int>* columns_ = nullptr;
  std::vector<std::string> fields_;
};

/// Largest CSV file a reader accepts [bytes]: 64 MiB by default, about an hour of 200 Hz IMU rows.
/// The readers keep every sample in memory (and the estimator's replay merges them once more), so
/// a larger file is refused up front with a message instead of taking several times its size in
/// memory (a 100 MB ranges.csv took 665 MB). The environment variable MESHNAV_MAX_CSV_MB raises or
/// lowers it (whole MiB, > 0; another value throws std::runtime_error naming it); docs/faults.md.
uint64_t maxCsvBytes();

/// Reads a comma separated file with a header line. A leading '#' on the header is ignored
/// (TUM files), and so is a UTF-8 byte order mark before it. Blank lines and lines starting with
/// '#' after the header are skipped.
class CsvReader {
 public:
  /// Opens and reads the header. Throws std::runtime_error("file: ...") when missing/unreadable,
  /// empty, larger than maxCsvBytes(), or when a column of `required` is absent.
  CsvReader(const std::string& path, const std::vector<std::string>& required);
  /// Calls `fn` for every data row. Rows with a wrong field count are reported to `diag` as
  /// "<basename>:bad_row" and skipped.
  void forEach(const std::function<void(const CsvRow&)>& fn, Diagnostics& diag);
  const std::vector<std::string>& header() const { return header_; }

 private:
  std::string path_;
  std::vector<std::string> header_;
  std::map<std::string, int> columns_;
};

/// Time column `col` [s] of a row. A value that is missing, not a finite number, or beyond
/// ±kMaxTimeSeconds (common/time.h: it would not fit a Timestamp) is reported with file:line as
/// "<key>:bad_time" and gives nullopt (the caller skips the row).
std::optional<Timestamp> parseRowTime(const CsvRow& r, const std::string& key, Diagnostics& d,
                                      const std::string& col = "t");

/// Base name of a path, for counter keys ("ranges.csv").
std::string baseName(const std::string& path);

/// What every reader of a time-stamped CSV does: the rows of `path` (columns `required`), a row
/// whose time does not parse reported (parseRowTime) and skipped, every other row given to
/// `sample(row, t, key)` (`key` the file's base name, for counters), which returns the sample to
/// keep or nullopt to skip the row (after reporting why). In file order.
template <class T, class Sample>
std::vector<T> readTimedRows(const std::string& path, const std::vector<std::string>& required, Diagnostics& diag,
                             Sample&& sample) {
  CsvReader reader(path, required);
  const std::string key = baseName(path);
  std::vector<T> out;
  reader.forEach(
      [&](const CsvRow& r) {
        const std::optional<Timestamp> t = parseRowTime(r, key, diag);
        if (!t) return;
        std::optional<T> s = sample(r, *t, key);
        if (!s) return;
        if (!out.empty() && *t < out.back().t)
          diag.report(key + ":time_backwards", r.where() + ": t=" + formatSeconds(*t) +
                                                   " s is earlier than the previous row's (" +
                                                   formatSeconds(out.back().t) + " s)");
        out.push_back(std::move(*s));
      },
      diag);
  return out;
}

}  // namespace meshnav
