#pragma once
/// @file diagnostics.h
/// @brief Counters for bad or rejected input. Every reader and node reports what it dropped here
/// (with a logged message naming file:line or channel) instead of crashing or passing it on.

#include <cstdint>
#include <map>
#include <mutex>
#include <string>

namespace meshnav {

class Diagnostics {
 public:
  /// Count one event of `kind` (e.g. "ranges.csv:nan_range") and log `message` as a warning.
  /// Only the first `max_logged_per_kind` messages of a kind are logged; all are counted.
  void report(const std::string& kind, const std::string& message);
  /// Count without logging.
  void count(const std::string& kind, int64_t n = 1);
  int64_t get(const std::string& kind) const;
  int64_t total() const;
  std::map<std::string, int64_t> snapshot() const;
  void merge(const Diagnostics& other);
  /// One line "kind=n, kind=n" (empty string when nothing was counted).
  std::string summary() const;
  int max_logged_per_kind = 5;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, int64_t> counts_;
};

}  // namespace meshnav
