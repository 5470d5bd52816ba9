#pragma once
/// @file time.h
/// @brief Strong time type of the core. On the wire and in files time is `int64 utime` (µs) or
/// decimal seconds; inside the libraries it is always a `Timestamp`.
///
/// Conversion from seconds refuses what an int64 of microseconds cannot hold: `fromSec` throws
/// std::out_of_range for a value that is not finite or beyond ±`kMaxTimeSeconds`, and
/// `tryFromSec` returns nullopt (what every file reader uses: the row is reported and skipped).

#include <cmath>
#include <compare>
#include <cstdint>
#include <optional>
#include <string>

namespace meshnav {

/// Largest |time| or |duration| accepted from seconds [s]: 4e12 s (about 127 000 years), so
/// that the sum of two such values still fits an int64 of microseconds (which ends at 9.22e12 s).
/// No data comes near it; a value beyond it is garbage.
inline constexpr double kMaxTimeSeconds = 4.0e12;

namespace time_detail {
/// Throws std::out_of_range naming `s` (out of line: keeps <stdexcept> and formatting out of here).
[[noreturn]] void throwOutOfRange(double s);
constexpr bool fits(double s) { return s == s && s <= kMaxTimeSeconds && s >= -kMaxTimeSeconds; }
constexpr int64_t toUs(double s) {
  if (!fits(s)) throwOutOfRange(s);
  return static_cast<int64_t>(std::llround(s * 1e6));
}
}  // namespace time_detail

/// A time span in microseconds (signed).
struct Duration {
  int64_t us = 0;
  /// Throws std::out_of_range when `s` is not finite or |s| > kMaxTimeSeconds.
  static constexpr Duration fromSec(double s) { return Duration{time_detail::toUs(s)}; }
  static constexpr Duration fromMs(double ms) { return Duration{time_detail::toUs(ms * 1e-3)}; }
  /// nullopt when `s` is not finite or |s| > kMaxTimeSeconds.
  static constexpr std::optional<Duration> tryFromSec(double s) {
    if (!time_detail::fits(s)) return std::nullopt;
    return fromSec(s);
  }
  constexpr double sec() const { return static_cast<double>(us) * 1e-6; }
  constexpr auto operator<=>(const Duration&) const = default;
  constexpr Duration operator+(Duration o) const { return {us + o.us}; }
  constexpr Duration operator-(Duration o) const { return {us - o.us}; }
  constexpr Duration operator-() const { return {-us}; }
};

/// An instant: microseconds since the epoch of the data source (dataset time 0, or Unix epoch live).
/// It marks the instant at which a measured quantity was valid.
struct Timestamp {
  int64_t us = 0;
  /// Throws std::out_of_range when `s` is not finite or |s| > kMaxTimeSeconds.
  static constexpr Timestamp fromSec(double s) { return Timestamp{time_detail::toUs(s)}; }
  /// nullopt when `s` is not finite or |s| > kMaxTimeSeconds.
  static constexpr std::optional<Timestamp> tryFromSec(double s) {
    if (!time_detail::fits(s)) return std::nullopt;
    return fromSec(s);
  }
  static constexpr Timestamp fromUtime(int64_t utime) { return Timestamp{utime}; }
  constexpr double sec() const { return static_cast<double>(us) * 1e-6; }
  constexpr int64_t utime() const { return us; }
  constexpr auto operator<=>(const Timestamp&) const = default;
  constexpr Timestamp operator+(Duration d) const { return {us + d.us}; }
  constexpr Timestamp operator-(Duration d) const { return {us - d.us}; }
  constexpr Duration operator-(Timestamp o) const { return {us - o.us}; }
};

/// "12.345678" seconds, the form used in every CSV file (any int64, INT64_MIN included).
std::string formatSeconds(Timestamp t);

}  // namespace meshnav
