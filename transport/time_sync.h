#pragma once
/// @file time_sync.h
/// @brief Time across hosts (docs/deployment.md "Time across hosts"): the estimator's host is the
/// reference clock; every other host that stamps measurements (an anchor computer's uwb_bridge)
/// estimates its offset to it by request/reply exchanges on TIME_SYNC_REQUEST / TIME_SYNC
/// (common/clock_offset.h) and stamps its messages in the reference clock.
///
/// Receive times are LCM's (taken by its receive thread), so time a message waits in a busy
/// process's queue does not bias the estimate; the reply is sent at once, t3 = the wall clock then.

#include <cstdint>
#include <optional>
#include <string>

#include "common/clock_offset.h"
#include "common/time.h"
#include "transport/lcm_node.h"

namespace meshnav::transport {

/// Answers TIME_SYNC_REQUEST on `node` with TIME_SYNC, stamped with this host's wall clock.
void serveTimeSync(LcmNode& node);

/// The client side. Its *local clock* is this host's wall clock plus `injected_offset` (fault
/// injection: a host whose clock is off; 0 in a real deployment).
class TimeSyncClient {
 public:
  TimeSyncClient(LcmNode& node, std::string client, Duration injected_offset = Duration{0},
                 ClockOffsetOptions options = {});
  TimeSyncClient(const TimeSyncClient&) = delete;
  TimeSyncClient& operator=(const TimeSyncClient&) = delete;

  /// The local clock [µs since the Unix epoch].
  int64_t localNow() const;
  /// Sends one request now.
  void request();
  /// Sends a request when `period` of wall time has passed since the last one.
  void poll(Duration period);
  /// Sends `n` requests `gap` apart while handling replies; returns once an offset is known and
  /// `n` were sent, or after `timeout` (false: no reply).
  bool synchronize(int n, Duration gap, Duration timeout);
  /// Reference − local clock [µs], once a reply came.
  std::optional<int64_t> offset() const { return estimator_.offset(); }
  std::optional<int64_t> errorBound() const { return estimator_.errorBound(); }
  /// A stamp of the local clock in the reference clock (unchanged before the first reply; counted
  /// "time_sync:unsynchronized").
  Timestamp toReference(Timestamp local);
  int64_t replies() const { return estimator_.accepted(); }

 private:
  LcmNode& node_;
  std::string client_;
  Duration injected_;
  ClockOffsetEstimator estimator_;
  int64_t seq_ = 0;
  int64_t last_request_wall_ = 0;
};

}  // namespace meshnav::transport
