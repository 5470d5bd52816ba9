#pragma once
/// @file time.h
/// @brief Strong time type of the core. On the wire and in files time is `int64 utime` (µs) or
/// decimal seconds; inside the libraries it is always a `Timestamp`.

#include <cmath>
#include <compare>
#include <cstdint>
#include <string>

namespace meshnav {

/// A time span in microseconds (signed).
struct Duration {
  int64_t us = 0;
  static constexpr Duration fromSec(double s) { return Duration{static_cast<int64_t>(std::llround(s * 1e6))}; }
  static constexpr Duration fromMs(double ms) { return Duration{static_cast<int64_t>(std::llround(ms * 1e3))}; }
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
  static constexpr Timestamp fromSec(double s) { return Timestamp{static_cast<int64_t>(std::llround(s * 1e6))}; }
  static constexpr Timestamp fromUtime(int64_t utime) { return Timestamp{utime}; }
  constexpr double sec() const { return static_cast<double>(us) * 1e-6; }
  constexpr int64_t utime() const { return us; }
  constexpr auto operator<=>(const Timestamp&) const = default;
  constexpr Timestamp operator+(Duration d) const { return {us + d.us}; }
  constexpr Timestamp operator-(Duration d) const { return {us - d.us}; }
  constexpr Duration operator-(Timestamp o) const { return {us - o.us}; }
};

/// "12.345678" seconds, the form used in every CSV file.
std::string formatSeconds(Timestamp t);

}  // namespace meshnav
