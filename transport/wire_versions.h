#pragma once
/// @file wire_versions.h
/// @brief Messages of an earlier version of their type, read as the current one (older logs,
/// calibrator journals, a process of an older build): lcmtypes/previous/README.md.
///
/// The version before issue 36 (package `meshnav_pre36`) is the current one without the trailing
/// `int64_t sender_id` (one per struct that got it: 8 bytes, 16 for `estimator_cmd_t`, whose
/// nested `anchor_init_t` is its last field). So a message of that version is decoded as that
/// version first (which checks it completely), and its bytes, with the current fingerprint and
/// zeros appended, then decode as the current type with `sender_id` = 0: unknown.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

#include "meshnav/anchor_init_t.hpp"
#include "meshnav/anchors_t.hpp"
#include "meshnav/baro_t.hpp"
#include "meshnav/calib_cmd_t.hpp"
#include "meshnav/calib_status_t.hpp"
#include "meshnav/estimator_cmd_t.hpp"
#include "meshnav/estimator_status_t.hpp"
#include "meshnav/flight_state_t.hpp"
#include "meshnav/ground_truth_t.hpp"
#include "meshnav/height_t.hpp"
#include "meshnav/imu_t.hpp"
#include "meshnav/mission_status_t.hpp"
#include "meshnav/pose_t.hpp"
#include "meshnav/range_t.hpp"
#include "meshnav/time_sync_t.hpp"
#include "meshnav_pre36/anchor_init_t.hpp"
#include "meshnav_pre36/anchors_t.hpp"
#include "meshnav_pre36/baro_t.hpp"
#include "meshnav_pre36/calib_cmd_t.hpp"
#include "meshnav_pre36/calib_status_t.hpp"
#include "meshnav_pre36/estimator_cmd_t.hpp"
#include "meshnav_pre36/estimator_status_t.hpp"
#include "meshnav_pre36/flight_state_t.hpp"
#include "meshnav_pre36/ground_truth_t.hpp"
#include "meshnav_pre36/height_t.hpp"
#include "meshnav_pre36/imu_t.hpp"
#include "meshnav_pre36/mission_status_t.hpp"
#include "meshnav_pre36/pose_t.hpp"
#include "meshnav_pre36/range_t.hpp"
#include "meshnav_pre36/time_sync_t.hpp"

namespace meshnav::transport {

/// The previous version of LCM type `Msg` that is still read (`void`: none), and the bytes the
/// current version has more at its end (8 per `int64_t sender_id` added).
template <class Msg>
struct PreviousVersionOf {
  using type = void;
  static constexpr int kAddedBytes = 0;
};
#define MESHNAV_PREVIOUS_VERSION(T, senders)      \
  template <>                                     \
  struct PreviousVersionOf<meshnav::T> {          \
    using type = meshnav_pre36::T;                \
    static constexpr int kAddedBytes = 8 * senders; \
  }
MESHNAV_PREVIOUS_VERSION(anchor_init_t, 1);
MESHNAV_PREVIOUS_VERSION(anchors_t, 1);
MESHNAV_PREVIOUS_VERSION(baro_t, 1);
MESHNAV_PREVIOUS_VERSION(calib_cmd_t, 1);
MESHNAV_PREVIOUS_VERSION(calib_status_t, 1);
MESHNAV_PREVIOUS_VERSION(estimator_cmd_t, 2);  // its own and that of its last field, anchor_init_t
MESHNAV_PREVIOUS_VERSION(estimator_status_t, 1);
MESHNAV_PREVIOUS_VERSION(flight_state_t, 1);
MESHNAV_PREVIOUS_VERSION(ground_truth_t, 1);
MESHNAV_PREVIOUS_VERSION(height_t, 1);
MESHNAV_PREVIOUS_VERSION(imu_t, 1);
MESHNAV_PREVIOUS_VERSION(mission_status_t, 1);
MESHNAV_PREVIOUS_VERSION(pose_t, 1);
MESHNAV_PREVIOUS_VERSION(range_t, 1);
MESHNAV_PREVIOUS_VERSION(time_sync_t, 1);
#undef MESHNAV_PREVIOUS_VERSION

/// The fingerprint an encoded message starts with (big endian, as LCM writes it); 0 when it is
/// shorter than 8 bytes.
int64_t encodedFingerprint(const void* data, size_t size);
/// Writes `hash` into the first 8 bytes of `data` (big endian).
void writeFingerprint(void* data, int64_t hash);

/// Decodes `data` (`size` bytes) into `msg`, of the current version or of the previous one
/// (PreviousVersionOf, its sender_id then 0). Returns what LCM's decode returns (bytes read, < 0
/// when the bytes are not such a message; for the previous version: the bytes of the older
/// message) and sets `*older` when the previous version was read. May throw as LCM's decode does
/// (a corrupted length).
template <class Msg>
int decodeAnyVersion(const void* data, size_t size, Msg& msg, bool* older = nullptr) {
  if (older) *older = false;
  using Previous = typename PreviousVersionOf<Msg>::type;
  if constexpr (!std::is_void_v<Previous>) {
    if (encodedFingerprint(data, size) == Previous::getHash() && Previous::getHash() != Msg::getHash()) {
      Previous previous;
      const int n = previous.decode(data, 0, static_cast<int>(size));
      if (n < 0) return n;
      // The missing trailing sender_id fields as zeros (unknown sender).
      std::vector<uint8_t> upgraded(static_cast<size_t>(n) + PreviousVersionOf<Msg>::kAddedBytes, 0);
      std::memcpy(upgraded.data(), data, static_cast<size_t>(n));
      writeFingerprint(upgraded.data(), Msg::getHash());
      const int m = msg.decode(upgraded.data(), 0, static_cast<int>(upgraded.size()));
      if (m != static_cast<int>(upgraded.size())) return -1;
      if (older) *older = true;
      return n;
    }
  }
  return msg.decode(data, 0, static_cast<int>(size));
}

}  // namespace meshnav::transport
