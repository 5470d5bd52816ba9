#pragma once
/// @file switch_io.h
/// @brief What meshnav_netem_switch needs to keep its fault model honest on a loaded machine:
/// a datagram's delay counts from its arrival in the kernel (not from when the switch got to read
/// it), and the copies it sends after their delivery time are counted (the switch's own lag,
/// which --netem did not ask for; switch.yaml "behind").
#include <sys/types.h>

#include <cstdint>
#include <vector>

namespace meshnav::netem {

/// Copies sent, and how far past their delivery time.
struct SwitchLag {
  static constexpr int64_t kLateUs = 10'000;  ///< a copy sent later than this past its time is "late"
  int64_t sent = 0;                           ///< copies sent
  int64_t late = 0;                           ///< of them more than kLateUs past their delivery time
  int64_t max_us = 0;                         ///< the largest delay past a delivery time [µs]
  /// One copy sent `late_us` after its delivery time (<= 0: on time).
  void add(int64_t late_us);
};

/// Asks the kernel to stamp every datagram `fd` receives (SO_TIMESTAMP); false when it refuses.
bool enableReceiveStamps(int fd);

/// Reads one waiting datagram of `fd` into `buf` (without waiting). `arrived_us` is the kernel's
/// arrival time [µs since the Unix epoch], or `fallback_us` when the datagram carries none.
/// Returns its size, or < 0 when none is waiting (errno set by recvmsg).
ssize_t receiveStamped(int fd, std::vector<uint8_t>& buf, int64_t fallback_us, int64_t& arrived_us);

}  // namespace meshnav::netem
