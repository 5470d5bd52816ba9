#pragma once
/// @file convert_internals.h
/// @brief What the two translation units of the LCM conversions share (convert.cpp: measurements,
/// estimates, calibration; convert_status.cpp: status and commands). Internal to meshnav_transport.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace meshnav::transport::convert_internal {

inline constexpr size_t kMaxArray = std::numeric_limits<int16_t>::max();  // wire counts are int16

/// A vector's size as a wire count, clamped to kMaxArray (the encoder then writes that many).
template <class T>
int16_t clampedCount(const std::vector<T>& v) {
  return static_cast<int16_t>(std::min(v.size(), kMaxArray));
}

}  // namespace meshnav::transport::convert_internal
